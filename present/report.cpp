#include "present/report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "render/provenance.h"

namespace flexure::present {

namespace {

// Round-off noise below 1e-14 (relative to unit vectors) printed as an exact zero.
double clean(double v) { return std::abs(v) < 1e-14 ? 0.0 : v; }

nlohmann::ordered_json optionalBool(const std::optional<bool>& b) {
  return b ? nlohmann::ordered_json(*b) : nlohmann::ordered_json(nullptr);
}

constexpr long kMaxJsonBasisEntries = 2'000'000;

}  // namespace

nlohmann::ordered_json countsJson(const Scene& scene, const engine::RigidityReport& rep) {
  const engine::ConstraintSystem& sys = scene.model->system();
  nlohmann::ordered_json j;
  j["title"] = scene.title;
  j["scene"] = scene.path;
  j["system"] = scene.type;
  j["dimension"] = sys.dimension();
  j["vertices"] = sys.numVertices();
  j["pinned"] = sys.numPinned();
  j["variables"] = rep.variables;
  j["equations"] = rep.equations;
  j["rigidity_rank"] = rep.rank;
  j["trivial_inf_flexes"] = rep.trivial;
  j["nontrivial_inf_flexes"] = rep.nontrivial;
  j["stress_dim"] = rep.stresses;
  j["inf_rigid"] = rep.inf_rigid;
  return j;
}

nlohmann::ordered_json analysisJson(const Scene& scene, const engine::RigidityReport& rep) {
  const engine::ConstraintSystem& sys = scene.model->system();
  nlohmann::ordered_json j = countsJson(scene, rep);
  j["prestress_stable"] = optionalBool(rep.prestress_stable);
  j["second_order_rigid"] = optionalBool(rep.second_order_rigid);
  j["rigid"] = engine::toString(rep.rigid);
  j["reason"] = rep.reason;
  // How the second-order questions were decided, and the flex that `flex = "auto"` follows.
  nlohmann::ordered_json so;
  so["seed"] = scene.analysis.seed;
  so["stress_margin"] = std::isnan(rep.stress_margin) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(rep.stress_margin);
  if (rep.blocking_stress.size() > 0 && rep.blocking_stress.size() <= kMaxJsonBasisEntries) {
    nlohmann::ordered_json w = nlohmann::ordered_json::array();
    for (int i = 0; i < rep.blocking_stress.size(); ++i) w.push_back(clean(rep.blocking_stress[i]));
    so["blocking_stress"] = w;
  }
  so["blocked_flex_search"] = rep.blocked_flex_note;
  so["homotopy_paths"] = rep.homotopy_paths;
  so["motion_check_change"] =
      std::isnan(rep.motion_check_change) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(rep.motion_check_change);
  // A second-order "rigid" checked by moving (directions tried), and a motion that contradicted
  // it (null: none).
  so["moves_checked"] = rep.second_order_moves;
  so["contradiction"] = rep.contradiction.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(rep.contradiction);
  nlohmann::ordered_json af = nlohmann::ordered_json::array();
  for (int i = 0; i < rep.auto_flex.size(); ++i) af.push_back(clean(rep.auto_flex[i]));
  so["auto_flex"] = af;
  so["auto_flex_note"] = rep.auto_flex_note;
  j["second_order"] = so;
  nlohmann::ordered_json num;
  num["method"] = rep.method;
  num["rank_tolerance"] = scene.analysis.rank_tolerance;
  num["threshold"] = rep.tolerance;
  num["sigma_max"] = rep.sigma_max;
  num["sigma_smallest_kept"] = rep.sigma_smallest_kept;
  num["sigma_largest_dropped"] = rep.sigma_largest_dropped;
  num["gap"] = rep.sigma_largest_dropped > 0 ? nlohmann::ordered_json(rep.sigma_smallest_kept / rep.sigma_largest_dropped)
                                             : nlohmann::ordered_json(nullptr);
  j["numerics"] = num;
  j["index_base"] = scene.index_base;
  // Flexes as velocity fields on every vertex (pinned vertices get zero), in basis order.
  if (rep.flex_basis_computed &&
      static_cast<long>(rep.flex_basis.size()) * 2 <= kMaxJsonBasisEntries) {
    nlohmann::ordered_json flexes = nlohmann::ordered_json::array();
    for (int c = 0; c < rep.flex_basis.cols(); ++c) {
      const engine::Matrix f = sys.velocityField(rep.flex_basis.col(c));
      nlohmann::ordered_json field = nlohmann::ordered_json::array();
      for (int v = 0; v < sys.numVertices(); ++v) {
        nlohmann::ordered_json vec = nlohmann::ordered_json::array();
        for (int k = 0; k < sys.dimension(); ++k) vec.push_back(clean(f(k, v)));
        field.push_back(vec);
      }
      flexes.push_back(field);
    }
    j["nontrivial_flex_basis"] = flexes;
  }
  if (rep.stress_basis_computed && static_cast<long>(rep.stress_basis.size()) <= kMaxJsonBasisEntries) {
    j["equation_labels"] = sys.equationLabels(scene.index_base);
    nlohmann::ordered_json stresses = nlohmann::ordered_json::array();
    for (int c = 0; c < rep.stress_basis.cols(); ++c) {
      nlohmann::ordered_json w = nlohmann::ordered_json::array();
      for (int i = 0; i < rep.stress_basis.rows(); ++i) w.push_back(clean(rep.stress_basis(i, c)));
      stresses.push_back(w);
    }
    j["stress_basis"] = stresses;
  }
  if (rep.exact) j["exact"] = true;
  if (rep.certificate) {
    nlohmann::ordered_json c;
    c["inf_rigid"] = optionalBool(rep.certificate->inf_rigid);
    c["flexible"] = optionalBool(rep.certificate->flexible);
    c["prestress_stable"] = optionalBool(rep.certificate->prestress_stable);
    c["reason"] = rep.certificate->reason;
    if (!std::isnan(rep.certificate->sigma_lower_bound)) c["sigma_lower_bound"] = rep.certificate->sigma_lower_bound;
    j["certificate"] = c;
    // The verdict is proved (sweep --where "certified").
    j["certified"] = rep.certificate->proves(rep.rigid);
  }
  j["warnings"] = rep.warnings;
  j["flexure"] = provenanceJson(scene.analysis.seed);
  return j;
}

nlohmann::ordered_json provenanceJson(std::optional<std::uint64_t> seed) {
  nlohmann::ordered_json p;
  p["version"] = render::flexureVersion();
  p["commit"] = render::flexureCommit();
  p["build_type"] = render::flexureBuildType();
  p["command"] = render::commandLine();
  if (seed) p["seed"] = *seed;
  return p;
}

std::string analysisText(const Scene& scene, const engine::RigidityReport& rep) {
  const engine::ConstraintSystem& sys = scene.model->system();
  std::ostringstream o;
  o.precision(3);
  auto yesno = [](const std::optional<bool>& b) {
    return b ? (*b ? "yes" : "no") : "undecided";
  };
  o << (scene.title.empty() ? scene.path : scene.title) << "  (" << scene.type << ", "
    << sys.dimension() << "D)\n";
  o << "  " << sys.numVertices() << " vertices (" << sys.numPinned() << " pinned), "
    << rep.variables << " variables, " << rep.equations << " equations\n";
  o << "  rigidity matrix rank " << rep.rank << "  [" << rep.method << "; sigma_max " << rep.sigma_max
    << ", smallest kept " << rep.sigma_smallest_kept << ", largest dropped "
    << rep.sigma_largest_dropped << ", threshold " << rep.tolerance << "]\n";
  o << "  infinitesimal flexes " << rep.inf_flexes << " = " << rep.trivial << " trivial + "
    << rep.nontrivial << " nontrivial\n";
  o << "  equilibrium stresses " << rep.stresses << "\n";
  o << "  infinitesimally rigid: " << (rep.inf_rigid ? "yes" : "no")
    << "   prestress stable: " << yesno(rep.prestress_stable)
    << "   second-order rigid: " << yesno(rep.second_order_rigid) << "\n";
  o << "  rigid: " << engine::toString(rep.rigid) << " (" << rep.reason << ")\n";
  if (rep.certificate) {
    auto proved = [](const std::optional<bool>& b) { return b ? (*b ? "proved" : "disproved") : "not proved"; };
    o << "  " << (rep.exact ? "exact (rational arithmetic)" : "certified") << ": infinitesimally rigid "
      << proved(rep.certificate->inf_rigid) << ", prestress stable " << proved(rep.certificate->prestress_stable)
      << ", flexible " << proved(rep.certificate->flexible) << " (" << rep.certificate->reason << ")\n";
  }
  if (rep.auto_flex.size() > 0) {
    o << "  auto flex:";
    for (int i = 0; i < rep.auto_flex.size(); ++i) o << " " << clean(rep.auto_flex[i]);
    o << "  (" << rep.auto_flex_note << ")\n";
  }
  for (const auto& w : rep.warnings) o << "  warning: " << w << "\n";
  return o.str();
}

std::string coefficientsText(const std::vector<double>& c) {
  std::string s = "(";
  char buf[64];
  for (size_t i = 0; i < c.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%.3g", c[i]);
    s += (i ? ", " : "") + std::string(buf);
  }
  return s + ")";
}

}  // namespace flexure::present
