// The SVG writer (render/vector.h): by hand, shapes as SVG elements with a class per part,
// shaded tubes and balls as gradients, text as <text>.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "render/provenance.h"
#include "render/text.h"
#include "render/utf8.h"
#include "render/vector_common.h"

namespace flexure::render::vector_detail {

namespace {

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char ch : cleanText(s)) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string svgClass(const std::string& role) {
  std::string c;
  for (char ch : role) c += ch == ' ' ? '-' : ch;
  return c;
}

std::string svgFill(const Color& c) {
  std::string s = "fill=\"" + hex(c) + "\"";
  if (c.a < 1) s += " fill-opacity=\"" + num(c.a) + "\"";
  return s;
}

}  // namespace

std::string svg(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::string defs, body;
  int gradients = 0;
  std::map<std::string, std::string> balls;  // colour -> gradient id
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    body += "<g class=\"panel\" clip-path=\"url(#panel" + std::to_string(k) + ")\">\n";
    defs += "<clipPath id=\"panel" + std::to_string(k) + "\"><rect x=\"" + num(panel.x) + "\" y=\"" + num(panel.y) +
            "\" width=\"" + num(panel.view.width) + "\" height=\"" + num(panel.view.height) + "\"/></clipPath>\n";
    for (const Prim& p : panels[k]) {
      // The part's id (its vertices, "bar-1-2"), unique in the figure: panels after the first
      // prefix theirs ("p2-bar-1-2").
      const std::string cls = "class=\"" + svgClass(p.role) + "\"" +
                              (p.id.empty() ? "" : " id=\"" + (k ? "p" + std::to_string(k + 1) + "-" : "") + p.id + "\"");
      const std::string plain = "class=\"" + svgClass(p.role) + "\"";  // a second element of the part
      switch (p.kind) {
        case Prim::Fill: {
          body += "<polygon " + cls + " points=\"";
          for (size_t i = 0; i < p.pts.size(); ++i) body += (i ? " " : "") + num(p.pts[i][0]) + "," + num(p.pts[i][1]);
          body += "\" " + svgFill(p.fill) + "/>\n";
          break;
        }
        case Prim::Line: {
          std::string stroke = hex(p.fill);
          if (p.shaded) {
            double len = 0;
            const P2 n = normalOf(p, &len);
            const P2 m{0.5 * (p.pts[0][0] + p.pts[1][0]), 0.5 * (p.pts[0][1] + p.pts[1][1])};
            const double r = 0.5 * p.width;
            const std::string id = "tube" + std::to_string(gradients++);
            defs += "<linearGradient id=\"" + id + "\" gradientUnits=\"userSpaceOnUse\" x1=\"" + num(m[0] - r * n[0]) +
                    "\" y1=\"" + num(m[1] - r * n[1]) + "\" x2=\"" + num(m[0] + r * n[0]) + "\" y2=\"" +
                    num(m[1] + r * n[1]) + "\">";
            for (double s : kTubeStops)
              defs += "<stop offset=\"" + num(0.5 * (s + 1)) + "\" stop-color=\"" + hex(tubeColor(p.fill, n, s)) + "\"/>";
            defs += "</linearGradient>\n";
            stroke = "url(#" + id + ")";
          }
          body += "<line " + cls + " x1=\"" + num(p.pts[0][0]) + "\" y1=\"" + num(p.pts[0][1]) + "\" x2=\"" +
                  num(p.pts[1][0]) + "\" y2=\"" + num(p.pts[1][1]) + "\" stroke=\"" + stroke + "\"";
          if (p.fill.a < 1) body += " stroke-opacity=\"" + num(p.fill.a) + "\"";
          body += " stroke-width=\"" + num(p.width) + "\"";
          if (p.dash > 0)
            body += " stroke-linecap=\"butt\" stroke-dasharray=\"" + num(p.dash) + " " + num(p.gap) + "\"";
          else
            body += p.butt ? " stroke-linecap=\"butt\"" : " stroke-linecap=\"round\"";
          body += "/>\n";
          break;
        }
        case Prim::Circle: {
          std::string fill = svgFill(p.fill);
          if (p.shaded) {
            const std::string key = hex(p.fill);
            auto it = balls.find(key);
            if (it == balls.end()) {
              const std::string id = "ball" + std::to_string(gradients++);
              defs += "<radialGradient id=\"" + id + "\" cx=\"0.5\" cy=\"0.5\" r=\"0.5\" fx=\"" +
                      num(0.5 + 0.5 * kHighlightX) + "\" fy=\"" + num(0.5 + 0.5 * kHighlightY) + "\">";
              for (double t : kBallStops)
                defs += "<stop offset=\"" + num(t) + "\" stop-color=\"" + hex(ballColor(p.fill, t)) + "\"/>";
              defs += "</radialGradient>\n";
              it = balls.emplace(key, id).first;
            }
            fill = "fill=\"url(#" + it->second + ")\"";
            if (p.fill.a < 1) fill += " fill-opacity=\"" + num(p.fill.a) + "\"";
          }
          body += "<circle " + cls + " cx=\"" + num(p.pts[0][0]) + "\" cy=\"" + num(p.pts[0][1]) + "\" r=\"" +
                  num(p.radius) + "\" " + fill + "/>\n";
          if (p.width > 0)  // the outline, inside the disc
            body += "<circle " + plain + " cx=\"" + num(p.pts[0][0]) + "\" cy=\"" + num(p.pts[0][1]) + "\" r=\"" +
                    num(std::max(0.0, p.radius - 0.5 * p.width)) + "\" fill=\"none\" stroke=\"" + hex(p.stroke) +
                    "\"" + (p.stroke.a < 1 ? " stroke-opacity=\"" + num(p.stroke.a) + "\"" : std::string()) +
                    " stroke-width=\"" + num(p.width) + "\"/>\n";
          break;
        }
        case Prim::Text: {
          const char* anchor = p.align < 0 ? "start" : p.align > 0 ? "end" : "middle";
          body += "<text " + cls + " x=\"" + num(p.pts[0][0]) + "\" y=\"" + num(p.pts[0][1]) + "\" font-size=\"" +
                  num(p.size) + "\" text-anchor=\"" + anchor + "\" dominant-baseline=\"central\"" +
                  (p.bold ? " font-weight=\"bold\"" : "") + " " + svgFill(p.fill) +
                  (p.halo > 0 ? " stroke=\"" + hex(p.stroke) + "\" stroke-width=\"" + num(p.halo) +
                                    "\" stroke-linejoin=\"round\" paint-order=\"stroke\""
                              : std::string()) +
                  ">" + xmlEscape(p.text) +
                  "</text>\n";
          break;
        }
      }
    }
    body += "</g>\n";
  }
  std::string o = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  // The size: pixels at 96 per inch, else points (a figure sized in length units).
  const auto size = [&](int px) {
    return fig.dpi == 96 ? std::to_string(px) : num(px * fig.pointsPerPixel()) + "pt";
  };
  o += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + size(fig.width) +
       "\" height=\"" + size(fig.height) + "\" viewBox=\"0 0 " + std::to_string(fig.width) + " " +
       std::to_string(fig.height) + "\" font-family=\"" + xmlEscape(fontFamily(defaultFont())) + ", sans-serif\">\n";
  if (!fig.title.empty()) o += "<title>" + xmlEscape(fig.title) + "</title>\n";
  o += "<metadata>" + xmlEscape(creatorText()) + "</metadata>\n";
  o += "<defs>\n" + defs + "</defs>\n";
  o += "<rect class=\"background\" width=\"100%\" height=\"100%\" " + svgFill(fig.background) + "/>\n";
  return o + body + "</svg>\n";
}

}  // namespace flexure::render::vector_detail
