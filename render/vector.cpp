#include "render/vector.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "render/vector_common.h"

namespace flexure::render {

bool vectorFormatOf(const std::string& extension, VectorFormat& format) {
  if (extension == "svg") format = VectorFormat::Svg;
  else if (extension == "pdf") format = VectorFormat::Pdf;
  else if (extension == "tex") format = VectorFormat::Tikz;
  else return false;
  return true;
}

VectorFigure singlePanel(const DrawList& list, const View& view, const std::string& title) {
  VectorFigure f;
  f.width = view.width, f.height = view.height;
  f.background = view.background;
  f.panels.push_back({&list, view, 0, 0});
  f.title = title;
  return f;
}

std::string vectorDocument(const VectorFigure& figure, VectorFormat format) {
  std::vector<std::vector<vector_detail::Prim>> panels;
  for (const VectorPanel& p : figure.panels) panels.push_back(vector_detail::flatten(p));
  switch (format) {
    case VectorFormat::Svg: return vector_detail::svg(figure, panels);
    case VectorFormat::Pdf: return vector_detail::pdf(figure, panels);
    case VectorFormat::Tikz: return vector_detail::tikz(figure, panels);
  }
  throw std::logic_error("unknown vector format");
}

}  // namespace flexure::render
