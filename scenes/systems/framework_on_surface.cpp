// [system] type = "framework_on_surface": a framework in 3D whose vertices stay on the surface
// f(x, y, z) = 0 given as an expression (compiled with exact derivatives).
#include "engine/systems/framework_on_surface.h"
#include "scenes/expression.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

// f(x, y, z) from a scene string, with exact derivatives.
class ExpressionField final : public engine::ScalarField {
 public:
  explicit ExpressionField(CompiledExpression e) : e_(std::move(e)) {}
  double value(const double* x) const override { return e_.value(x); }
  void evaluate(const double* x, double* f, double* g, double* h) const override { e_.evaluate(x, f, g, h); }
  std::string text() const override { return "\"" + e_.text() + "\""; }

 private:
  CompiledExpression e_;
};

std::unique_ptr<engine::Model> buildFrameworkOnSurface(const Reader& r, const toml::table& sys, int base, Matrix p) {
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto edges = toArrays<2>(readVertexLists(r, sys, "edges", vi, "an edge", 2, 2));
    const toml::node& sn = r.require(sys, "surface", "[system]");
    const std::string text = r.string(sn, "surface");
    std::shared_ptr<const engine::ScalarField> field;
    try {
      CompiledExpression e(text, {"x", "y", "z"});
      if (!e.usesVariable(0) && !e.usesVariable(1) && !e.usesVariable(2))
        r.fail(sn, "surface \"" + excerpt(text) + "\" does not depend on x, y or z");
      field = std::make_shared<ExpressionField>(std::move(e));
    } catch (const ExpressionError& e) {
      r.fail(sn.source(), "surface: " + expressionMessage(e, text), e.offset + 1);
    }
    return std::make_unique<engine::FrameworkOnSurface>(p, std::move(edges), readPinned(r, sys, vi), field,
                                                        optionalFlag(r, sys, "project_start"), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType frameworkOnSurface() {
  return {"framework_on_surface", {3}, buildFrameworkOnSurface, "edge lengths, every vertex on f = 0",
          "`edges`, `surface = \"x^2 + y^2 - z^2 - 1\"` (3D), `project_start`",
          "the surface's isometries, found numerically"};
}

}  // namespace flexure::scenes::detail::systems
