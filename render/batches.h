// The render stages that need no GL: a DrawList and a View become vertex batches in pixels,
// in the order they are drawn. Polygons are triangulated in their own plane and split into
// opaque and translucent ones (back to front in 3D); shapes become one covering quad each,
// translucent ones last and back to front in 3D; labels are laid out as glyph quads per atlas.
// A DrawBackend (render/draw_backend.h) then rasterizes the batches.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "render/camera.h"
#include "render/draw_list.h"
#include "render/text.h"

namespace flexure::render {

// A vertex of a shape's covering quad: the shape's parameters travel with it (the fragment
// shader computes the signed distance).
struct ShapeVertex {
  float pos[3];
  float ends[4];    // a.xy, b.xy in px
  float params[4];  // kind, radius, outline, depth radius
  float fill[4];
  float stroke[4];
  float extra[4];   // pointing.xy (triangle) or dash, gap (segment)
  float depths[3];  // depth at a, depth at b, shaded
};

// A vertex of a flat triangle: polygons, and glyph quads (with atlas coordinates).
struct FlatVertex {
  float pos[3];
  float rgba[4];
  float uv[2];
};

struct TextBatch {
  int atlas_key = 0;  // 2 * pixel size + (regular weight)
  std::vector<FlatVertex> vertices;
};

struct FrameBatches {
  int width = 0, height = 0;
  Color background;
  bool depth = false;                           // 3D: depth-tested
  float fog = 0;                                // 3D: View::fog
  std::vector<FlatVertex> opaque_polygons;      // triangles
  std::vector<FlatVertex> translucent_polygons; // triangles, back to front in 3D
  std::vector<ShapeVertex> shapes;              // six vertices per shape
  size_t opaque_shape_vertices = 0;             // shapes[0, this) are opaque; the rest translucent
  std::vector<TextBatch> text;                  // ascending atlas key
};

// The atlas for a key, made on first use (the renderer caches them).
using AtlasSource = std::function<GlyphAtlas&(int key)>;

void buildPolygonBatches(const DrawList& list, const Projector& project, bool depth, FrameBatches& out);
void buildShapeBatch(const DrawList& list, const Projector& project, bool depth, FrameBatches& out);
void layoutLabels(const DrawList& list, const Projector& project, int height, const AtlasSource& atlas,
                  FrameBatches& out);
// The labels to draw, in order: every label, but a declutter label whose box (`width` of its
// text in px by its size, about its anchor) overlaps one placed before is moved to the first
// free place of four beside its anchor (offset and aside_color), or left out; declutter labels
// are placed nearest first in 3D, in their order in 2D.
std::vector<Label> placedLabels(const DrawList& list, const Projector& project, int height, bool depth,
                                 const std::function<double(const Label&)>& width);
// All of them.
FrameBatches buildFrame(const DrawList& list, const View& view, const AtlasSource& atlas);

// A polygon's colour as drawn: in 3D a shaded polygon is lit by its (Newell) normal, both
// sides alike.
Color polygonColor(const Polygon& poly, const Projector& project, bool depth);

// A colour faded toward `background` by `fog` times the depth's place between the near (-0.8)
// and far (0.8) side of the view's box: the same rule as the shape shader's.
Color fogged(const Color& c, double depth, const Color& background, double fog);
// How far fogged() fades toward the background at that depth (0..fog).
double fogAmount(double depth, double fog);

// The halo under a 3D label of colour `text`: the background behind dark text, near-black
// behind light text (white numbers on dark balls); its width in px for a label of `size`.
Color haloColor(const Color& text, const Color& background);
double haloWidth(double size);

// Ear clipping of a simple polygon given in 2D (indices into pts); returns triangles.
std::vector<int> triangulate(const std::vector<std::array<double, 2>>& pts);

}  // namespace flexure::render
