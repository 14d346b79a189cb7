#include "engine/active_set.h"

#include <stdexcept>

namespace flexure::engine {

namespace {

[[noreturn]] void notStick(const char* what) {
  throw std::logic_error(std::string("Inequalities::") + what + ": only a set with the Stick rule has it");
}

}  // namespace

std::function<bool(const Vector&)> Inequalities::admissibleFrom(const Vector& start) const {
  (void)start;
  return {};
}

std::string Inequalities::outsideReason(const Vector& y, int index_base) const {
  (void)y, (void)index_base;
  return {};
}

double Inequalities::tolerance() const { notStick("tolerance"); }
double Inequalities::smallestSlack(const Matrix&, Id*) const { notStick("smallestSlack"); }
std::vector<Inequalities::Id> Inequalities::active() const { notStick("active"); }
bool Inequalities::isActive(Id) const { notStick("isActive"); }
std::vector<int> Inequalities::vertices(Id) const { notStick("vertices"); }
std::string Inequalities::name(Id) const { notStick("name"); }
std::shared_ptr<const Model> Inequalities::withActive(const Matrix&) const { notStick("withActive"); }

bool piecewise(const Model& model) {
  const Inequalities* q = model.inequalities();
  return q && (q->rule() == Inequalities::Rule::Stick || q->rule() == Inequalities::Rule::Release);
}

}  // namespace flexure::engine
