// Vector figures (SVG, PDF, TikZ), filmstrips and the one view of a path: the SVG parsed as XML
// (Python's xml.etree) with one element per bar and per joint; the PDF read back by poppler
// (pdfinfo, pdftoppm at 96 dpi) and compared with the PNG of the same frame; the TikZ text's
// styles and elements; a still of sample K equal to frame K of the animation.
#include <catch2/catch.hpp>

#include <regex>
#include <tuple>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>

#include "pipeline/pipeline.h"
#include "present/animation.h"
#include "present/frames.h"
#include "present/writers.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/provenance.h"
#include "render/vector.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
using test::example;
namespace fs = std::filesystem;

namespace {

render::Renderer& renderer() {
  static render::Renderer r;
  return r;
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexure_vector_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string shell(const std::string& cmd) {
  std::FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buf[512];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  CHECK(pclose(p) == 0);
  return out;
}

// "WIDTH HEIGHT count(class=a) count(class=b) ..." of an SVG, parsed as XML.
std::string svgCounts(const fs::path& svg, const std::vector<std::string>& classes) {
  std::string list;
  for (const auto& c : classes) list += "'" + c + "',";
  return shell("/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E\n"
               "r = E.parse(sys.argv[1]).getroot()\n"
               "assert r.tag == '{http://www.w3.org/2000/svg}svg', r.tag\n"
               "cs = [e.get('class') for e in r.iter()]\n"
               "print(r.get('width'), r.get('height'), *[cs.count(c) for c in [" +
               list + "]])\" " + svg.string());
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Mean absolute difference per channel (0..255) of two images of one size, and the share of
// pixels that differ by more than 64 in some channel.
std::pair<double, double> difference(const render::Image& a, const render::Image& b) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  double sum = 0;
  long far = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]);
        sum += d;
        worst = std::max(worst, d);
      }
      far += worst > 64;
    }
  const double n = static_cast<double>(a.width) * a.height;
  return {sum / (3 * n), static_cast<double>(far) / n};
}

render::Image readPng(const fs::path& p) {
  const std::string bytes = slurp(p);
  return render::decodePng(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
}

}  // namespace

TEST_CASE("vector: an SVG frame has one element per bar, joint, pin and label, and text as text", "[outputs][vector]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=40"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const fs::path svg = scratch("dw.svg");
  present::writeFrame(scene, &m.path, 20, false, svg.string(), renderer());
  // 15 bars, 11 joints, 3 pins, 11 labels.
  CHECK(svgCounts(svg, {"bar", "joint", "pin", "label", "panel"}) == "1000 1000 15 11 3 11 1\n");
  const std::string text = slurp(svg);
  CHECK(count(text, "<text class=\"label\"") == 11);
  CHECK(text.find(">11</text>") != std::string::npos);
  CHECK(text.find("<title>Cuspidal double Watt mechanism</title>") != std::string::npos);
  // 3D: shaded balls and tubes by gradients; the octahedron's 12 bars and 6 joints.
  const scenes::Scene oct = example("bricard_octahedron", {"motion.steps=0"});
  const fs::path svg3 = scratch("oct.svg");
  present::writeFrame(oct, nullptr, 0, false, svg3.string(), renderer());
  CHECK(svgCounts(svg3, {"bar", "joint"}) == "1000 1000 12 6\n");
  const std::string t3 = slurp(svg3);
  CHECK(count(t3, "<linearGradient") == 12);
  // Fog: the joints' colour fades with depth (a gradient per shade); 3D labels have halos.
  CHECK(count(t3, "<radialGradient") > 1);
  CHECK(count(t3, "paint-order=\"stroke\"") == 6);
  CHECK(count(text, "paint-order") == 0);  // 2D: none
  const scenes::Scene clear = example("bricard_octahedron", {"motion.steps=0", "render.fog=0"});
  present::writeFrame(clear, nullptr, 0, false, svg3.string(), renderer());
  CHECK(count(slurp(svg3), "<radialGradient") == 1);  // one for the joints' colour
}

TEST_CASE("vector: non-ASCII text stays text in SVG and PDF, and markup is escaped", "[outputs][vector]") {
  render::DrawList list;
  list.segment({0, 0, 0}, {1, 1, 0}, 4, {0, 0, 0, 1});
  render::Label l;
  l.at = {0.5, 0.5, 0};
  l.text = "Peaucellier\u2013Lipkin, \u03b8 \u2208 [0, \u03c0], M\u00f6bius <&> 50% a_b \xff";
  l.size = 20;
  list.labels.push_back(l);
  render::View view;
  view.width = 400, view.height = 200;
  view.lo = {-0.2, -0.2, 0}, view.hi = {1.2, 1.2, 0};
  const render::VectorFigure fig = render::singlePanel(list, view, "t\u03b8");
  const std::string svg = render::vectorDocument(fig, render::VectorFormat::Svg);
  CHECK(svg.find("Peaucellier\u2013Lipkin, \u03b8 \u2208 [0, \u03c0], M\u00f6bius &lt;&amp;&gt; 50% a_b \xef\xbf\xbd</text>") !=
        std::string::npos);
  const fs::path svg_file = scratch("text.svg");
  std::ofstream(svg_file) << svg;
  CHECK(svgCounts(svg_file, {"text", "line"}) == "400 200 1 1\n");
  const std::string tex = render::vectorDocument(fig, render::VectorFormat::Tikz);
  CHECK(tex.find("M\u00f6bius <\\&> 50\\% a\\_b") != std::string::npos);
  const fs::path pdf = scratch("text.pdf");
  std::ofstream(pdf, std::ios::binary) << render::vectorDocument(fig, render::VectorFormat::Pdf);
  // poppler reads the text back as text, in UTF-8.
  const std::string back = shell("pdftotext -enc UTF-8 " + pdf.string() + " -");
  CHECK(back.find("M\u00f6bius") != std::string::npos);
  CHECK(back.find("\u03b8 \u2208 [0, \u03c0]") != std::string::npos);
}

TEST_CASE("vector: a PDF frame is one page of the PNG's size in points and rasterises to the PNG", "[outputs][vector]") {
  for (const char* name : {"double_watt", "bricard_octahedron", "cube", "disk_packing"}) {
    INFO(name);
    const scenes::Scene scene = example(name, {"motion.steps=6", "render.width=400", "render.height=300"});
    const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
    const fs::path pdf = scratch(std::string(name) + ".pdf"), png = scratch(std::string(name) + ".png");
    present::writeFrame(scene, &m.path, 3, false, pdf.string(), renderer());
    present::writeFrame(scene, &m.path, 3, false, png.string(), renderer());
    const std::string info = shell("pdfinfo " + pdf.string() + " | tr -s ' '");
    CHECK(info.find("Pages: 1\n") != std::string::npos);
    CHECK(info.find("Page size: 300 x 225 pts") != std::string::npos);
    CHECK(info.find("Creator: " + render::creatorText() + "\n") != std::string::npos);  // which flexure
    const fs::path raster = scratch(std::string(name) + "_pdf");
    shell("pdftoppm -r 96 -png -singlefile " + pdf.string() + " " + raster.string());
    const auto [mean, far] = difference(readPng(png), readPng(raster.string() + ".png"));
    CHECK(mean < 4.0);   // anti-aliasing and glyph rasterisation differ; nothing else
    CHECK(far < 0.01);
  }
}

TEST_CASE("vector: with SOURCE_DATE_EPOCH a PDF is the same bytes every time", "[outputs][vector]") {
  render::DrawList list;
  list.segment({0, 0, 0}, {1, 1, 0}, 4, {0, 0, 0, 1});
  render::View view;
  view.width = 100, view.height = 100;
  const render::VectorFigure fig = render::singlePanel(list, view, "t");
  ::setenv("SOURCE_DATE_EPOCH", "1764000000", 1);
  const std::string a = render::vectorDocument(fig, render::VectorFormat::Pdf);
  const std::string b = render::vectorDocument(fig, render::VectorFormat::Pdf);
  ::unsetenv("SOURCE_DATE_EPOCH");
  CHECK(a == b);
  CHECK(a.find("/CreationDate (20251124160000") != std::string::npos);
}

TEST_CASE("vector: TikZ is a standalone document with one named style per part", "[outputs][vector]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=10"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const fs::path tex = scratch("dw.tex");
  present::writeFrame(scene, &m.path, 5, false, tex.string(), renderer());
  const std::string t = slurp(tex);
  CHECK(t.find("\\documentclass[tikz]{standalone}") != std::string::npos);
  CHECK(count(t, "\\begin{tikzpicture}") == 1);
  CHECK(count(t, "\\end{tikzpicture}") == 1);
  for (const char* style : {"flexure bar/.style", "flexure joint/.style", "flexure pin/.style", "flexure label/.style"})
    CHECK(count(t, style) == 1);
  CHECK(count(t, "\\draw[flexure bar]") == 15);
  CHECK(count(t, "\\path[flexure joint]") == 11);
  CHECK(count(t, "\\fill[flexure pin]") == 3);
  CHECK(count(t, "\\node[flexure label") == 11);
  CHECK(count(t, "{") == count(t, "}"));
}

namespace {

// The crank (bar 1-2 from pin 1) of a drawing, in pixels, and the box of its joints on screen.
struct OnScreen {
  double crank = 0;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
};

OnScreen onScreen(const render::DrawList& list, const render::View& view) {
  const render::Projector project(view);
  std::vector<std::array<double, 3>> joints;
  for (const render::Shape& s : list.shapes)
    if (s.role && std::string(s.role) == "joint") joints.push_back(project(s.a));
  REQUIRE(joints.size() == 11);
  OnScreen o;
  o.crank = std::hypot(joints[0][0] - joints[1][0], joints[0][1] - joints[1][1]);
  for (const auto& j : joints)
    o.x0 = std::min(o.x0, j[0]), o.x1 = std::max(o.x1, j[0]), o.y0 = std::min(o.y0, j[1]), o.y1 = std::max(o.y1, j[1]);
  return o;
}

}  // namespace

TEST_CASE("vector: a still of sample K is the animation's drawing of K, framed on the sample", "[outputs][vector]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=60", "render.width=300", "render.height=240"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const present::Animation anim(scene, m.path, 300, 240);
  for (int k : {0, 30, 60}) {
    INFO("sample " << k);
    const present::FrameDrawing still = present::frameDrawing(scene, &m.path, k, false);
    CHECK(still.sample == k);
    // The same configuration as the animation draws (its alignment): the joints where the
    // animation's drawing of sample K has them, in world coordinates.
    const present::Animation::Still frame = anim.sampleDrawing(k, {});
    std::vector<render::Point3> a, b;
    for (const render::Shape& s : still.list.shapes)
      if (s.role && std::string(s.role) == "joint") a.push_back(s.a);
    for (const render::Shape& s : frame.list.shapes)
      if (s.role && std::string(s.role) == "joint") b.push_back(s.a);
    CHECK(a == b);
    // Framed on the sample: its joints' box is centred in the image (the window is square in
    // world units and centred on each axis' data).
    const OnScreen o = onScreen(still.list, still.view);
    CHECK(0.5 * (o.x0 + o.x1) == Approx(150).margin(0.5));
    CHECK(0.5 * (o.y0 + o.y1) == Approx(120).margin(0.5));
  }
}

TEST_CASE("vector: filmstrips side by side and overlaid, in PNG and SVG", "[outputs][vector]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=60", "render.width=300", "render.height=240"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const fs::path svg = scratch("strip.svg"), png = scratch("strip.png");
  const present::Written w = present::writeFilmstrip(scene, &m.path, {0, 30, 60}, false, svg.string(), renderer());
  CHECK(w.summary == "900x240, samples 0,30,60");
  CHECK(svgCounts(svg, {"bar", "joint", "panel"}) == "900 240 45 33 3\n");
  present::writeFilmstrip(scene, &m.path, {0, 30, 60}, false, png.string(), renderer());
  const render::Image strip = readPng(png);
  CHECK(strip.width == 900);
  CHECK(strip.height == 240);
  CHECK(svgCounts(svg, {"caption"}) == "900 240 3\n");  // "sample K" under each panel; no event caption
  CHECK(slurp(svg).find(">sample 30</text>") != std::string::npos);
  // One scale for every panel: the crank (a fixed bar in the plane) has one length on screen,
  // the distance of the first two joints of each panel in the SVG.
  const std::string text = slurp(svg);
  std::vector<double> panel_cranks;
  const std::regex joint(R"re(class="joint"[^>]*cx="([0-9.]+)" cy="([0-9.]+)")re");
  std::vector<std::pair<double, double>> centres;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), joint); it != std::sregex_iterator(); ++it)
    centres.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  REQUIRE(centres.size() == 33);
  for (size_t p = 0; p < 3; ++p)
    panel_cranks.push_back(std::hypot(centres[11 * p].first - centres[11 * p + 1].first,
                                      centres[11 * p].second - centres[11 * p + 1].second));
  CHECK(panel_cranks[0] > 10);
  CHECK(panel_cranks[1] == Approx(panel_cranks[0]).margin(0.03));
  CHECK(panel_cranks[2] == Approx(panel_cranks[0]).margin(0.03));
  // Overlaid: one panel, every sample's bars, the earlier ones fading, the last one's labels.
  const scenes::Scene over = example("double_watt", {"motion.steps=60", "render.width=300", "render.height=240",
                                                      "render.filmstrip_overlay=true"});
  const fs::path svg2 = scratch("overlay.svg");
  present::writeFilmstrip(over, &m.path, {0, 30, 60}, false, svg2.string(), renderer());
  CHECK(svgCounts(svg2, {"bar", "label", "panel"}) == "300 240 45 11 1\n");
  CHECK(slurp(svg2).find("stroke-opacity=\"0.2\"") != std::string::npos);
}

TEST_CASE("vector: projection plots in SVG, PDF and TikZ", "[outputs][vector]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=40", "render.width=400", "render.height=400"});
  pipeline::Study study(scene);
  for (const char* ext : {"svg", "pdf", "tex"}) {
    const fs::path f = scratch(std::string("projection.") + ext);
    study.write({f.string(), scenes::OutputKind::Projection}, f.string(), [&]() -> render::Renderer& { return renderer(); });
    const std::string t = slurp(f);
    if (std::string(ext) == "svg") CHECK(t.find("<text") != std::string::npos);
    if (std::string(ext) == "pdf") CHECK(shell("pdfinfo " + f.string() + " | tr -s ' '").find("Pages: 1\n") != std::string::npos);
    if (std::string(ext) == "tex") CHECK(t.find("\\begin{tikzpicture}") != std::string::npos);
  }
}

TEST_CASE("vector: TikZ compiles with pdflatex to a page of the figure's size", "[outputs][vector]") {
  // A 2D frame (with a Latin-1 title), a 3D frame (shaded balls, fog, label halos) and a
  // projection plot; each compiled as written, its PDF one page of width x height px at 0.75 bp.
  const scenes::Scene dw = example("double_watt", {"motion.steps=10", "render.width=400", "render.height=300"});
  const scenes::Scene oct = example("bricard_octahedron", {"motion.steps=0", "render.width=300", "render.height=300"});
  const pipeline::Motion m = pipeline::track(dw, dw.motion.steps);
  const fs::path dir = scratch("tikz");
  fs::create_directories(dir);
  present::writeFrame(dw, &m.path, 5, false, (dir / "frame2d.tex").string(), renderer());
  present::writeFrame(oct, nullptr, 0, false, (dir / "frame3d.tex").string(), renderer());
  pipeline::Study study(dw);
  study.write({(dir / "plot.tex").string(), scenes::OutputKind::Projection}, (dir / "plot.tex").string(),
              [&]() -> render::Renderer& { return renderer(); });
  for (const auto& [name, w, h] : std::vector<std::tuple<std::string, double, double>>{
           {"frame2d", 300, 225}, {"frame3d", 225, 225}, {"plot", 300, 225}}) {
    INFO(name);
    shell("cd " + dir.string() + " && pdflatex -interaction=nonstopmode -halt-on-error " + name +
          ".tex > " + name + ".out 2>&1; echo");
    REQUIRE(fs::exists(dir / (name + ".pdf")));
    const std::string info = shell("pdfinfo " + (dir / (name + ".pdf")).string() + " | tr -s ' '");
    CHECK(info.find("Pages: 1\n") != std::string::npos);
    double pw = 0, ph = 0;
    REQUIRE(info.find("Page size: ") != std::string::npos);
    CHECK(std::sscanf(info.c_str() + info.find("Page size: "), "Page size: %lf x %lf pts", &pw, &ph) == 2);
    CHECK(pw == Approx(w).margin(0.05));
    CHECK(ph == Approx(h).margin(0.05));
    // Text in outline fonts, not METAFONT bitmaps.
    CHECK(shell("pdffonts " + (dir / (name + ".pdf")).string()).find("Type 3") == std::string::npos);
  }
}

TEST_CASE("vector: origami panels and creases by assignment, mountains solid and valleys dashed", "[outputs][vector]") {
  const scenes::Scene miura = example("miura_ori", {"motion.steps=60"});
  const pipeline::Motion m = pipeline::track(miura, miura.motion.steps);
  const fs::path svg = scratch("miura.svg");
  present::writeFrame(miura, &m.path, 60, false, svg.string(), renderer());
  // 16 panels, 40 edges: 16 on the boundary, and the 24 creases of the assignment.
  size_t mountains = 0, valleys = 0;
  for (char c : miura.model->geometry().bars.kinds) mountains += c == 'M', valleys += c == 'V';
  CHECK(mountains + valleys == 24);
  CHECK(svgCounts(svg, {"face", "mountain", "valley", "boundary"}) ==
        "1000 1000 16 " + std::to_string(mountains) + " " + std::to_string(valleys) + " 16\n");
  const std::string t = slurp(svg);
  CHECK(static_cast<size_t>(count(t, "stroke-dasharray")) >= valleys);  // valleys dashed
}
