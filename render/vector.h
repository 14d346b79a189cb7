// Vector output: the same DrawList and View that the raster renderer draws, written as SVG
// (by hand: shapes as SVG elements with a class per part, text as <text>), PDF (cairo: text as
// text with the font embedded) or TikZ (a standalone LaTeX document whose tikzpicture draws
// with one named style per part, "flexure bar", "flexure joint", ...). Everything is projected
// by the renderer's camera (render/camera.h) into pixels; in 3D shapes and polygons are painted
// back to front (depth of their centre), balls and tubes shaded by gradients as the raster
// renderer lights them. A figure can hold several panels (a filmstrip) side by side.
#pragma once

#include <string>
#include <vector>

#include "render/draw_list.h"

namespace flexure::render {

enum class VectorFormat { Svg, Pdf, Tikz };

// "svg", "pdf", "tex"; false for anything else.
bool vectorFormatOf(const std::string& extension, VectorFormat& format);

// One picture of a figure: its drawing, and where its view's image lies in the figure (px,
// from the top left).
struct VectorPanel {
  const DrawList* list = nullptr;
  View view;
  double x = 0, y = 0;
};

struct VectorFigure {
  int width = 1000, height = 1000;  // px
  // Pixels per inch: a figure sized in length units ([render] width = "8cm") has its scene's dpi
  // (its PNG says so, and the SVG, PDF and TikZ have that size); else 96 (1 px = 0.75 pt).
  double dpi = 96;
  double pointsPerPixel() const { return 72.0 / dpi; }
  Color background{1, 1, 1, 1};
  std::vector<VectorPanel> panels;
  std::string title;  // the document's title (metadata), may be empty
};

// The whole file's bytes. Throws std::runtime_error if cairo fails (PDF).
std::string vectorDocument(const VectorFigure& figure, VectorFormat format);

// One panel filling the figure.
VectorFigure singlePanel(const DrawList& list, const View& view, const std::string& title = "");

}  // namespace flexure::render
