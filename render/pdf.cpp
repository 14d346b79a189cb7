// The PDF writer (render/vector.h): drawn by cairo in points, text as text with the font
// embedded, the creation date SOURCE_DATE_EPOCH's where it is set.
#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/provenance.h"
#include "render/reproducible.h"
#include "render/text.h"
#include "render/utf8.h"
#include "render/vector_common.h"

namespace flexure::render::vector_detail {

namespace {

void cairoColor(cairo_t* cr, const Color& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

cairo_status_t appendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string pdf(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::string bytes;
  const double kPt = fig.pointsPerPixel();
  cairo_surface_t* surface =
      cairo_pdf_surface_create_for_stream(appendToString, &bytes, fig.width * kPt, fig.height * kPt);
  if (!fig.title.empty()) cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, cleanText(fig.title).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, creatorText().c_str());
  // The creation date is the clock's, unless SOURCE_DATE_EPOCH fixes it (reproducible files).
  if (const long long t = sourceDateEpoch(); t >= 0) {
    const std::time_t tt = static_cast<std::time_t>(t);
    std::tm utc{};
    gmtime_r(&tt, &utc);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATE_DATE, date);
  }
  cairo_t* cr = cairo_create(surface);
  const std::string family = fontFamily(defaultFont());
  cairo_scale(cr, kPt, kPt);
  cairoColor(cr, fig.background);
  cairo_paint(cr);
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    cairo_save(cr);
    cairo_rectangle(cr, panel.x, panel.y, panel.view.width, panel.view.height);
    cairo_clip(cr);
    for (const Prim& p : panels[k]) {
      switch (p.kind) {
        case Prim::Fill:
          cairo_new_path(cr);
          for (const P2& q : p.pts) cairo_line_to(cr, q[0], q[1]);
          cairo_close_path(cr);
          cairoColor(cr, p.fill);
          cairo_fill(cr);
          break;
        case Prim::Line: {
          cairo_new_path(cr);
          cairo_move_to(cr, p.pts[0][0], p.pts[0][1]);
          cairo_line_to(cr, p.pts[1][0], p.pts[1][1]);
          cairo_set_line_width(cr, p.width);
          if (p.dash > 0) {
            const double d[2] = {p.dash, p.gap};
            cairo_set_dash(cr, d, 2, 0);
            cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
          } else {
            cairo_set_dash(cr, nullptr, 0, 0);
            cairo_set_line_cap(cr, p.butt ? CAIRO_LINE_CAP_BUTT : CAIRO_LINE_CAP_ROUND);
          }
          cairo_pattern_t* pattern = nullptr;
          if (p.shaded) {
            const P2 n = normalOf(p);
            const P2 m{0.5 * (p.pts[0][0] + p.pts[1][0]), 0.5 * (p.pts[0][1] + p.pts[1][1])};
            const double r = 0.5 * p.width;
            pattern = cairo_pattern_create_linear(m[0] - r * n[0], m[1] - r * n[1], m[0] + r * n[0], m[1] + r * n[1]);
            for (double s : kTubeStops) {
              const Color c = tubeColor(p.fill, n, s);
              cairo_pattern_add_color_stop_rgba(pattern, 0.5 * (s + 1), c.r, c.g, c.b, c.a);
            }
            cairo_set_source(cr, pattern);
          } else {
            cairoColor(cr, p.fill);
          }
          cairo_stroke(cr);
          if (pattern) cairo_pattern_destroy(pattern);
          break;
        }
        case Prim::Circle: {
          const double x = p.pts[0][0], y = p.pts[0][1];
          cairo_new_path(cr);
          cairo_arc(cr, x, y, p.radius, 0, 2 * M_PI);
          cairo_pattern_t* pattern = nullptr;
          if (p.shaded) {
            pattern = cairo_pattern_create_radial(x + kHighlightX * p.radius, y + kHighlightY * p.radius, 0, x, y, p.radius);
            for (double t : kBallStops) {
              const Color c = ballColor(p.fill, t);
              cairo_pattern_add_color_stop_rgba(pattern, t, c.r, c.g, c.b, c.a);
            }
            cairo_set_source(cr, pattern);
          } else {
            cairoColor(cr, p.fill);
          }
          cairo_fill(cr);
          if (pattern) cairo_pattern_destroy(pattern);
          if (p.width > 0) {
            cairo_new_path(cr);
            cairo_arc(cr, x, y, std::max(0.0, p.radius - 0.5 * p.width), 0, 2 * M_PI);
            cairo_set_line_width(cr, p.width);
            cairo_set_dash(cr, nullptr, 0, 0);
            cairoColor(cr, p.stroke);
            cairo_stroke(cr);
          }
          break;
        }
        case Prim::Text: {
          const std::string text = cleanText(p.text);
          cairo_select_font_face(cr, family.c_str(), CAIRO_FONT_SLANT_NORMAL,
                                 p.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
          cairo_set_font_size(cr, p.size);
          cairo_text_extents_t e;
          cairo_text_extents(cr, text.c_str(), &e);
          // As the raster renderer lays labels out: the ink centred vertically on the anchor,
          // its left end, centre or right end at the anchor.
          const double x = p.pts[0][0] - e.x_bearing - 0.5 * (1 + p.align) * e.width;
          const double y = p.pts[0][1] - (e.y_bearing + 0.5 * e.height);
          if (p.halo > 0) {
            cairo_move_to(cr, x, y);
            cairo_text_path(cr, text.c_str());
            cairoColor(cr, p.stroke);
            cairo_set_line_width(cr, p.halo);
            cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
            cairo_set_dash(cr, nullptr, 0, 0);
            cairo_stroke(cr);
          }
          cairo_move_to(cr, x, y);
          cairoColor(cr, p.fill);
          cairo_show_text(cr, text.c_str());
          break;
        }
      }
    }
    cairo_restore(cr);
  }
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) throw std::runtime_error(std::string("cairo: ") + cairo_status_to_string(status));
  return bytes;
}

}  // namespace flexure::render::vector_detail
