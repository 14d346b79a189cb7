// Verdicts do not depend on the unit of length: every catalog scene, scaled by 1e-4 and 1e4,
// gets the same rank, counts and verdicts as at scale 1, and its motion check sees the same
// relative change. (Spherical disk packings are caps on the unit sphere: no unit of length.)
#include <catch2/catch.hpp>

#include <cmath>
#include <regex>
#include <sstream>

#include <toml++/toml.h>

#include "engine/rigidity.h"
#include "pipeline/pipeline.h"
#include "scenes/catalog.h"
#include "scenes/scene.h"

using namespace flexure;

namespace {

// The node times s (after floatify): numbers multiplied, expression strings wrapped; arrays
// element by element.
void scaleNode(toml::node& n, double s) {
  if (auto* a = n.as_array()) {
    for (auto& e : *a) scaleNode(e, s);
  } else if (auto* f = n.as_floating_point()) {
    *f = f->get() * s;
  } else if (auto* str = n.as_string()) {
    std::ostringstream o;
    o.precision(17);
    o << "(" << str->get() << ")*" << s;
    *str = o.str();
  }
}

// Integers inside arrays replaced by floats first, so that scaleNode can multiply them.
void floatify(toml::node& n) {
  if (auto* a = n.as_array())
    for (size_t k = 0; k < a->size(); ++k) {
      if (auto* i = a->get(k)->as_integer()) {
        const double v = static_cast<double>(i->get());
        a->replace(a->cbegin() + static_cast<std::ptrdiff_t>(k), v);
      } else {
        floatify(*a->get(k));
      }
    }
}

std::string scaled(const std::string& text, double s) {
  toml::table t = toml::parse(text);
  toml::table& sys = *t["system"].as_table();
  for (const char* key : {"vertices", "lengths", "radii"})
    if (toml::node* n = sys.get(key)) {
      floatify(*n);
      scaleNode(*n, s);
    }
  if (toml::node* r = sys.get("radius")) {
    const double v = r->value<double>().value();
    sys.insert_or_assign("radius", v * s);
  }
  if (auto* f = sys.get_as<std::string>("surface")) {
    std::ostringstream by;
    by.precision(17);
    by << "($1/" << s << ")";
    *f = std::regex_replace(f->get(), std::regex(R"(\b([xyz])\b)"), by.str());
  }
  if (toml::table* m = t["motion"].as_table())
    for (const char* key : {"target_length", "step_size"})
      if (const auto v = (*m)[key].value<double>()) m->insert_or_assign(key, *v * s);
  std::ostringstream out;
  out << t;
  return out.str();
}

}  // namespace

TEST_CASE("scale: every catalog scene gets the same verdicts at 1e-4, 1 and 1e4", "[scenes][engine]") {
  int compared = 0;
  for (const scenes::CatalogEntry& e : scenes::catalog()) {
    const toml::table t = toml::parse(e.text);
    const std::string type = t["system"]["type"].value_or(std::string());
    if (type == "spherical_disk_packing" || type == "catalog") continue;
    INFO(e.name);
    const engine::RigidityReport one = pipeline::analyze(scenes::loadSceneFromString(e.text, "catalog:" + std::string(e.name)));
    for (double s : {1e-4, 1e4}) {
      INFO("scale " << s);
      const std::string text = scaled(e.text, s);
      INFO(text);
      const engine::RigidityReport r = pipeline::analyze(scenes::loadSceneFromString(text, "scaled.toml"));
      CHECK(r.rank == one.rank);
      CHECK(r.trivial == one.trivial);
      CHECK(r.nontrivial == one.nontrivial);
      CHECK(r.stresses == one.stresses);
      CHECK(r.inf_rigid == one.inf_rigid);
      CHECK(r.prestress_stable == one.prestress_stable);
      CHECK(r.second_order_rigid == one.second_order_rigid);
      CHECK(r.rigid == one.rigid);
      if (std::isnan(one.motion_check_change)) {
        CHECK(std::isnan(r.motion_check_change));
      } else {
        // From a regular start the short path is the same path at every scale. From a start
        // with a stress (the double Watt's two Watt linkages in phase: 2 flexes, 1 stress) the
        // path leaves a singular point, where which nearby point the corrector lands on is a
        // matter of rounding: there the change agrees to 1 % (0.0547 against 0.0548), far
        // from the 1e-3 that decides the verdict, which is compared exactly above.
        const double tol = one.stresses == 0 ? 1e-6 : 1e-2;
        CHECK(std::abs(r.motion_check_change - one.motion_check_change) <= tol * one.motion_check_change + 1e-12);
      }
      ++compared;
    }
  }
  CHECK(compared >= 80);  // every type but the disk packing, twice
}
