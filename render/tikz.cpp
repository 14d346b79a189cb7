// The TikZ writer (render/vector.h): a standalone LaTeX document whose tikzpicture draws with
// one named style per part ("flexure bar", "flexure joint", ...), colours defined by name.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "render/provenance.h"
#include "render/utf8.h"
#include "render/vector_common.h"

namespace flexure::render::vector_detail {

namespace {

std::string texEscape(const std::string& s) {
  std::string o;
  for (char ch : cleanText(s)) {
    switch (ch) {
      case '\\': o += "\\textbackslash{}"; break;
      case '{': o += "\\{"; break;
      case '}': o += "\\}"; break;
      case '$': o += "\\$"; break;
      case '&': o += "\\&"; break;
      case '#': o += "\\#"; break;
      case '%': o += "\\%"; break;
      case '_': o += "\\_"; break;
      case '~': o += "\\textasciitilde{}"; break;
      case '^': o += "\\textasciicircum{}"; break;
      default: o += ch;
    }
  }
  return o;
}

// A TikZ style: what a part looks like. Parts whose look equals their role's style use the
// style alone; others add what differs.
struct TikzLook {
  std::string color;  // a defined colour's name
  double opacity = 1, width = 0, dash = 0, gap = 0, size = 0, outline = 0;
  std::string outline_color;
  bool shaded = false, bold = true, butt = false;
  int align = 0;
  int fog = 0;  // 3D: percent faded toward the background (not part of the style: "NAME fog=P")
  bool operator==(const TikzLook& o) const {
    return color == o.color && opacity == o.opacity && width == o.width && dash == o.dash && gap == o.gap &&
           size == o.size && outline == o.outline && outline_color == o.outline_color && shaded == o.shaded &&
           bold == o.bold && align == o.align && butt == o.butt;
  }
};

// Pixels to big points at the figure's resolution (0.75 at 96 per inch).
std::string bp(double px, double k) { return num(k * px) + "bp"; }

std::string tikzOptions(Prim::Kind kind, const TikzLook& l, double k) {
  std::string o;
  const auto add = [&](const std::string& s) { o += (o.empty() ? "" : ", ") + s; };
  switch (kind) {
    case Prim::Fill:
      add("fill=" + l.color);
      if (l.opacity < 1) add("fill opacity=" + num(l.opacity));
      break;
    case Prim::Line:
      add("draw=" + l.color), add("line width=" + bp(l.width, k));
      if (l.opacity < 1) add("draw opacity=" + num(l.opacity));
      if (l.dash > 0) add("dash pattern=on " + bp(l.dash, k) + " off " + bp(l.gap, k) + ", line cap=butt");
      else add(l.butt ? "line cap=butt" : "line cap=round");
      break;
    case Prim::Circle:
      if (l.shaded) add("ball color=" + l.color);
      else add("fill=" + l.color);
      if (l.opacity < 1) add("opacity=" + num(l.opacity));
      if (l.outline > 0) add("draw=" + l.outline_color), add("line width=" + bp(l.outline, k));
      break;
    case Prim::Text:
      add("text=" + l.color);
      if (l.opacity < 1) add("text opacity=" + num(l.opacity));
      add("inner sep=0pt");
      add(std::string("anchor=") + (l.align < 0 ? "west" : l.align > 0 ? "east" : "center"));
      add("font=\\fontsize{" + num(k * l.size) + "}{" + num(1.2 * k * l.size) + "}\\selectfont" +
          (l.bold ? "\\bfseries" : ""));
      break;
  }
  return o;
}

// The options of a TikZ option list ("a=1, b=2" -> {"a=1", "b=2"}); options hold no commas.
std::vector<std::string> split(const std::string& options) {
  std::vector<std::string> out;
  for (size_t at = 0; at <= options.size();) {
    const size_t comma = std::min(options.find(", ", at), options.size());
    out.push_back(options.substr(at, comma - at));
    at = comma + 2;
  }
  return out;
}

}  // namespace

std::string tikz(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::map<std::string, std::string> colors;  // hex -> name
  std::string color_defs;
  const auto colorName = [&](const Color& c) {
    const std::string h = hex(c);
    auto it = colors.find(h);
    if (it == colors.end()) {
      const std::string name = "flexure" + std::string(1, static_cast<char>('A' + colors.size() % 26)) +
                               (colors.size() >= 26 ? std::to_string(colors.size() / 26) : "");
      char rgb[64];
      std::snprintf(rgb, sizeof rgb, "%d,%d,%d", channel(c.r), channel(c.g), channel(c.b));
      color_defs += "\\definecolor{" + name + "}{RGB}{" + rgb + "}\n";
      it = colors.emplace(h, name).first;
    }
    return it->second;
  };
  const std::string background = colorName(fig.background);
  // A part's look in its own colours; its fog apart (fog styles mix them with the background).
  const auto lookOf = [&](const Prim& p) {
    TikzLook l;
    l.fog = static_cast<int>(std::lround(100 * p.fog));
    l.color = colorName(l.fog > 0 ? p.own_fill : p.fill);
    l.opacity = std::round(p.fill.a * 100) / 100;
    if (p.kind == Prim::Line) l.width = p.width, l.dash = p.dash, l.gap = p.gap, l.butt = p.butt;
    if (p.kind == Prim::Circle) {
      l.shaded = p.shaded;
      l.outline = p.width;
      if (p.width > 0) l.outline_color = colorName(l.fog > 0 ? p.own_stroke : p.stroke);
    }
    if (p.kind == Prim::Text) l.size = p.size, l.bold = p.bold, l.align = p.align;
    return l;
  };
  // One style per (role, kind): the first part's look.
  std::map<std::pair<std::string, int>, TikzLook> styles;
  std::vector<std::pair<std::string, int>> style_order;
  std::map<std::string, int> kinds_of_role;
  std::map<std::pair<std::string, int>, bool> fogged_style;  // a part of the style's look is faded
  for (const auto& prims : panels)
    for (const Prim& p : prims) {
      const auto key = std::make_pair(p.role, static_cast<int>(p.kind));
      TikzLook look = lookOf(p);
      const int fog = look.fog;
      look.fog = 0;
      if (styles.emplace(key, look).second) {
        style_order.push_back(key);
        ++kinds_of_role[p.role];
      }
      if (fog > 0 && look == styles[key]) fogged_style[key] = true;
    }
  // A colour faded by `fog` percent toward the background, as xcolor mixes it.
  const auto faded = [&](const std::string& color, const std::string& percent) {
    return color + "!" + percent + "!" + background;
  };
  static const char* kKindNames[] = {"fill", "line", "disc", "text"};
  const auto styleName = [&](const std::pair<std::string, int>& key) {
    return "flexure " + key.first + (kinds_of_role[key.first] > 1 ? std::string(" ") + kKindNames[key.second] : "");
  };
  std::string body;
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    body += "  \\begin{scope}\n    \\clip (" + num(panel.x) + "," + num(panel.y) + ") rectangle (" +
            num(panel.x + panel.view.width) + "," + num(panel.y + panel.view.height) + ");\n";
    for (const Prim& p : panels[k]) {
      const auto key = std::make_pair(p.role, static_cast<int>(p.kind));
      TikzLook look = lookOf(p);
      const int fog = look.fog;
      look.fog = 0;
      std::string opt = styleName(key);
      if (look == styles[key]) {
        // Faded by depth: the style's own fog style, which mixes the style's colours.
        if (fog > 0) opt += ", " + styleName(key) + " fog=" + std::to_string(100 - fog);
      } else {
        if (fog > 0) {
          const std::string percent = std::to_string(100 - fog);
          look.color = faded(look.color, percent);
          if (!look.outline_color.empty()) look.outline_color = faded(look.outline_color, percent);
        }
        opt += ", " + tikzOptions(p.kind, look, fig.pointsPerPixel());
      }
      const auto at = [&](const P2& q) { return "(" + num(q[0]) + "," + num(q[1]) + ")"; };
      const std::string idComment = p.id.empty() ? "" : " % " + p.id;  // the part's vertices
      switch (p.kind) {
        case Prim::Fill: {
          body += "    \\fill[" + opt + "] ";
          for (const P2& q : p.pts) body += at(q) + " -- ";
          body += "cycle;\n";
          break;
        }
        case Prim::Line:
          body += "    \\draw[" + opt + "] " + at(p.pts[0]) + " -- " + at(p.pts[1]) + ";" + idComment + "\n";
          break;
        case Prim::Circle:
          // The radius in the picture's units (x = one pixel): as the pixels.
          body += std::string(look.shaded ? "    \\shade[" : "    \\path[") + opt + "] " + at(p.pts[0]) +
                  " circle[radius=" + num(p.radius) + "];" + idComment + "\n";
          break;
        case Prim::Text:
          body += "    \\node[" + opt + "] at " + at(p.pts[0]) + " {" + texEscape(p.text) + "};" + idComment + "\n";
          break;
      }
    }
    body += "  \\end{scope}\n";
  }
  std::string o = "% " + (fig.title.empty() ? std::string("A figure") : texEscape(fig.title)) +
                  ", drawn by flexure. Compile with pdflatex (lualatex or xelatex for text beyond Latin-1).\n"
                  "% Every part has a named style (\\tikzset below): restyle the bars, joints, ... there.\n"
                  "% Coordinates are the PNG's pixels (y down); 1 px = " + num(fig.pointsPerPixel()) + " bp.\n";
  // Latin Modern with T1 where installed; else the Type 1 Computer Modern that every TeX has
  // (T1 without Latin Modern or cm-super would make METAFONT draw bitmap fonts).
  o += "% " + creatorText() + "\n";
  o += "\\documentclass[tikz]{standalone}\n\\IfFileExists{lmodern.sty}{\\usepackage[T1]{fontenc}\\usepackage{lmodern}}{}\n"
       "\\usepackage[utf8]{inputenc}\n"
       "\\renewcommand{\\familydefault}{\\sfdefault}\n";
  o += color_defs;
  o += "\\tikzset{\n";
  for (const auto& key : style_order) {
    const TikzLook& look = styles[key];
    o += "  " + styleName(key) + "/.style={" + tikzOptions(static_cast<Prim::Kind>(key.second), look, fig.pointsPerPixel()) + "},\n";
    if (!fogged_style[key]) continue;
    // "NAME fog=P": P percent of the style's colours, the rest the background's (3D depth).
    TikzLook mixed = look;
    mixed.color = faded(look.color, "#1");
    if (!mixed.outline_color.empty()) mixed.outline_color = faded(look.outline_color, "#1");
    const auto kind = static_cast<Prim::Kind>(key.second);
    std::string colors;
    for (const std::string& part : split(tikzOptions(kind, mixed, fig.pointsPerPixel())))
      if (part.find('!') != std::string::npos) colors += (colors.empty() ? "" : ", ") + part;
    o += "  " + styleName(key) + " fog/.style={" + colors + "},\n";
  }
  o += "}\n\\begin{document}\n\\begin{tikzpicture}[x=" + num(fig.pointsPerPixel()) + "bp, y=-" +
       num(fig.pointsPerPixel()) + "bp]\n";
  o += "  \\fill[" + background + "] (0,0) rectangle (" + std::to_string(fig.width) + "," +
       std::to_string(fig.height) + ");\n";
  return o + body + "\\end{tikzpicture}\n\\end{document}\n";
}

}  // namespace flexure::render::vector_detail
