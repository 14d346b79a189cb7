// Figures at print size: [render] width and height as lengths ("8cm") give a raster at dpi that
// says so (PNG pHYs), vector documents of that size, and sizes in points whatever the figure's
// size; filmstrips in a grid with captions of the user's choice; a still that does not depend on
// the path's length. The expected numbers are computed here from the units' definitions
// (1 in = 2.54 cm = 72 pt), not taken from flexure.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <array>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "cli_common.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace flexure_cli_test;

namespace {

std::uint32_t bigEndian(const std::string& s, size_t at) {
  std::uint32_t v = 0;
  for (size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(s[at + k]);
  return v;
}

// A PNG's size and its pHYs chunk (pixels per metre, 0 when absent), read chunk by chunk.
struct PngInfo {
  std::uint32_t width = 0, height = 0, per_metre = 0;
};

PngInfo pngInfo(const fs::path& file) {
  const std::string s = readFile(file);
  REQUIRE(s.size() > 33);
  REQUIRE(s.compare(1, 3, "PNG") == 0);
  PngInfo info;
  for (size_t at = 8; at + 8 <= s.size();) {
    const std::uint32_t length = bigEndian(s, at);
    const std::string type = s.substr(at + 4, 4);
    if (type == "IHDR") info.width = bigEndian(s, at + 8), info.height = bigEndian(s, at + 12);
    if (type == "pHYs") {
      REQUIRE(bigEndian(s, at + 8) == bigEndian(s, at + 12));
      CHECK(s[at + 16] == 1);  // unit: the metre
      info.per_metre = bigEndian(s, at + 8);
    }
    at += 12 + length;
  }
  return info;
}

// Every number of an attribute in an SVG (e.g. the font sizes of the captions).
std::vector<double> attributeValues(const std::string& svg, const std::string& pattern) {
  std::vector<double> out;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back(std::stod((*it)[1].str()));
  return out;
}

}  // namespace

TEST_CASE("cli: a figure sized in lengths is that size in every format, with its text in points", "[cli]") {
  const fs::path d = scratchDir("figure_size");
  const std::string square = example("square");
  const std::string size = " --set render.width=8cm --set render.height=6cm";
  // 8 cm at 300 dpi: 8 / 2.54 * 300 = 944.88 px; 6 cm: 708.66 px.
  REQUIRE(run("render " + square + " -o " + (d / "a.png").string() + size).status == 0);
  const PngInfo png = pngInfo(d / "a.png");
  CHECK(png.width == 945);
  CHECK(png.height == 709);
  CHECK(png.per_metre == 11811);  // 300 / 0.0254
  // A figure in pixels states no resolution (as before).
  REQUIRE(run("render " + square + " -o " + (d / "px.png").string()).status == 0);
  CHECK(pngInfo(d / "px.png").per_metre == 0);
  CHECK(pngInfo(d / "px.png").width == 1000);
  // dpi changes the pixels, not the size.
  REQUIRE(run("render " + square + " -o " + (d / "b.png").string() + size + " --set render.dpi=150").status == 0);
  CHECK(pngInfo(d / "b.png").width == 472);  // 8 / 2.54 * 150 = 472.44
  CHECK(pngInfo(d / "b.png").per_metre == 5906);
  // A length and pixels: the pixels count at dpi (a catalog entry's height under a length width).
  REQUIRE(run("render double_watt -o " + (d / "c.png").string() + " --set render.width=6cm --set render.height=500").status == 0);
  CHECK(pngInfo(d / "c.png").width == 709);  // 6 / 2.54 * 300 = 708.66
  CHECK(pngInfo(d / "c.png").height == 500);
  CHECK(pngInfo(d / "c.png").per_metre == 11811);

  // The PDF's page and the SVG's size: 8 cm = 226.77 pt (to the pixel: 945 px at 300 dpi = 226.8 pt).
  REQUIRE(run("render " + square + " -o " + (d / "a.pdf").string() + size).status == 0);
  std::smatch m;
  const std::string pdf = readFile(d / "a.pdf");
  REQUIRE(std::regex_search(pdf, m, std::regex(R"(/MediaBox \[\s*0 0 ([0-9.]+) ([0-9.]+)\s*\])")));
  CHECK(std::stod(m[1]) == Approx(945 * 72.0 / 300).margin(0.01));
  CHECK(std::stod(m[2]) == Approx(709 * 72.0 / 300).margin(0.01));
  REQUIRE(run("render " + square + " -o " + (d / "a.svg").string() + size).status == 0);
  const std::string svg = readFile(d / "a.svg");
  CHECK(svg.find("width=\"226.8pt\" height=\"170.16pt\" viewBox=\"0 0 945 709\"") != std::string::npos);
  REQUIRE(run("render " + square + " -o " + (d / "a.tex").string() + size).status == 0);
  CHECK(readFile(d / "a.tex").find("[x=0.24bp, y=-0.24bp]") != std::string::npos);  // 72 / 300

  // Captions are 9 pt by default whatever the figure's size: 9 * 300 / 72 = 37.5 px at 300 dpi,
  // in a strip 16 cm wide as in one 8 cm wide. "font_size" in points sets them.
  const auto captionSizes = [&](const std::string& args) {
    const std::string f = (d / "strip.svg").string();
    const Result r = run("render " + square + " --samples 0,10,20 -o " + f + " " + args);
    INFO(r.err);
    REQUIRE(r.status == 0);
    return attributeValues(readFile(f), R"re(class="caption"[^>]*font-size="([0-9.]+)")re");
  };
  for (const char* w : {"16cm", "8cm"}) {
    const std::vector<double> sizes = captionSizes(std::string("--set render.width=") + w + " --set render.height=3cm");
    REQUIRE(sizes.size() == 3);
    for (double s : sizes) CHECK(s == Approx(37.5).margin(0.01));
  }
  for (double s : captionSizes("--set render.width=16cm --set render.height=3cm --set render.font_size=10pt"))
    CHECK(s == Approx(10 * 300 / 72.0).margin(0.01));
  // In a figure of pixels, points are at 96 per inch: 12 pt = 16 px.
  for (double s : captionSizes("--set render.font_size=12pt")) CHECK(s == Approx(16).margin(0.01));
}

TEST_CASE("cli: filmstrips in a grid, each panel captioned as asked", "[cli]") {
  const fs::path d = scratchDir("filmstrip_grid");
  const std::string square = example("square");
  const std::string f = (d / "s.png").string();
  // Six panels in three columns: two rows. In pixels each panel is width x height; sized in
  // lengths the whole grid is (12 cm x 8 cm at 100 dpi: 472 x 315 px, panels of 157 x 157).
  REQUIRE(run("render " + square + " --samples 0,4,8,12,16,20 -o " + f +
              " --set render.width=300 --set render.height=200 --set render.columns=3")
              .status == 0);
  CHECK(pngInfo(f).width == 900);
  CHECK(pngInfo(f).height == 400);
  REQUIRE(run("render " + square + " --samples 0,4,8,12 -o " + f +
              " --set render.width=300 --set render.height=200 --set render.columns=3")
              .status == 0);
  CHECK(pngInfo(f).height == 400);  // 4 panels in 3 columns: 2 rows
  REQUIRE(run("render " + square + " --samples 0,4,8,12,16,20 -o " + f +
              " --set render.width=12cm --set render.height=8cm --set render.dpi=100 --set render.columns=3")
              .status == 0);
  CHECK(pngInfo(f).width == 472);
  CHECK(pngInfo(f).height == 315);

  // {arc_length}: the length of the polygon through the samples' coordinates up to the panel's
  // sample, computed here from the path JSON of the same motion.
  const std::string p = (d / "p.json").string();
  REQUIRE(run("track " + square + " --quiet -o " + p + " --set motion.steps=30").status == 0);
  const json path = json::parse(readFile(fs::path(p)));
  std::vector<double> arc{0};
  for (size_t k = 1; k < path["samples"].size(); ++k) {
    double s = 0;
    for (size_t v = 0; v < path["samples"][k].size(); ++v)
      for (size_t c = 0; c < 2; ++c) {
        const double dx = path["samples"][k][v][c].get<double>() - path["samples"][k - 1][v][c].get<double>();
        s += dx * dx;
      }
    arc.push_back(arc.back() + std::sqrt(s));
  }
  const std::string svg = (d / "s.svg").string();
  const Result r = run("render " + square + " --samples 0,15,30 -o " + svg +
                       " --set motion.steps=30 --set 'render.caption=s = {arc_length}, sample {sample}'");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const std::string text = readFile(fs::path(svg));
  for (int k : {0, 15, 30}) {
    char expected[64];
    std::snprintf(expected, sizeof expected, "s = %.3g, sample %d<", arc[static_cast<size_t>(k)], k);
    INFO(expected);
    CHECK(text.find(expected) != std::string::npos);
  }
  CHECK(arc[30] > 0.1);  // the square moved
  // {distance:I:J}: the diagonal 1-3 from the path's positions.
  REQUIRE(run("render " + square + " --samples 0,30 -o " + svg +
              " --set motion.steps=30 --set 'render.caption=d = {distance:1:3}'").status == 0);
  for (int k : {0, 30}) {
    const auto& p = path["samples"][static_cast<size_t>(k)];
    const double dx = p[0][0].get<double>() - p[2][0].get<double>(), dy = p[0][1].get<double>() - p[2][1].get<double>();
    char expected[64];
    std::snprintf(expected, sizeof expected, "d = %.4g<", std::hypot(dx, dy));
    INFO(expected);
    CHECK(readFile(fs::path(svg)).find(expected) != std::string::npos);
  }
  // No captions.
  REQUIRE(run("render " + square + " --samples 0,15 -o " + svg + " --set 'render.caption='").status == 0);
  CHECK(readFile(fs::path(svg)).find("class=\"caption\"") == std::string::npos);
}

TEST_CASE("cli: a still of the start does not depend on the path's length, and has no event caption", "[cli]") {
  const fs::path d = scratchDir("still_orientation");
  for (const std::string name : {"cube", "square"}) {
    const std::string scene = example(name);
    std::string first;
    for (const std::string steps : {"0", "5", "80"}) {
      const std::string f = (d / (name + steps + ".svg")).string();
      const Result r = run("render " + scene + " -o " + f + " --set motion.steps=" + steps);
      INFO(name << " steps " << steps << ": " << r.err);
      REQUIRE(r.status == 0);
      const std::string text = readFile(fs::path(f));
      if (first.empty()) first = text;
      CHECK(text == first);
    }
  }
  // The pinned square's flat position is a singular event: its still has no caption.
  const std::string f = (d / "flat.svg").string();
  const Result r = run("render " + example("square_pinned") + " --sample 89 -o " + f);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(readFile(fs::path(f)).find("singular point") == std::string::npos);
}

TEST_CASE("cli: lengths that cannot be read are refused at their place in the file", "[cli]") {
  const fs::path d = scratchDir("figure_size_errors");
  const auto refused = [&](const std::string& render, const std::string& message, int line = 7) {
    const fs::path f = d / "s.toml";
    std::ofstream(f) << "[system]\ntype = \"framework\"\nvertices = [[0, 0], [1, 0], [1, 1]]\n"
                        "edges = [[1, 2], [2, 3]]\n\n[render]\n"
                     << render << "\n";
    const Result r = run("render " + f.string() + " -o " + (d / "x.png").string());
    INFO(render << " -> " << r.err);
    CHECK(r.status == 1);
    CHECK(r.err.find("s.toml:" + std::to_string(line) + ":") != std::string::npos);
    CHECK(r.err.find(message) != std::string::npos);
    CHECK_FALSE(fs::exists(d / "x.png"));
  };
  refused("width = \"8 furlongs\"", "width must be an integer or a length with its unit");
  refused("line_width = \"1 furlong\"", "line_width");
  refused("width = \"-3cm\"", "a positive length with its unit");
  refused("width = \"80cm\"", "at 300 dpi");
  refused("caption = \"t = {time}\"", "unknown field {time}");
  refused("caption = \"{distance:1:9}\"", "out of range");
  // Issue 62: a number that does not fit an int is refused, not wrapped (4294967297 was vertex 1),
  // at its column; a length's pixels are checked before they become an integer.
  refused("caption = \"{distance:4294967297:2}\"", "s.toml:7:22: caption: {distance:I:J}: vertex 4294967297 is out of range");
  refused("width = \"1e300in\"", "width is 3e+302 px at 300 dpi");
  refused("height = \"9.3e18px\"", "height is 9.3e+18 px");
  refused("font_size = \"900pt\"", "font_size is");
}

namespace {

struct SvgBar {
  std::string id, stroke;
  double width = 0;
  bool dashed = false;
};

// The bars of an SVG figure by their ids.
std::map<std::string, SvgBar> svgBars(const std::string& svg) {
  std::map<std::string, SvgBar> out;
  const std::regex line(R"re(<line class="bar" id="([^"]+)"[^>]*stroke="(#[0-9A-F]{6})" stroke-width="([0-9.]+)"([^>]*)>)re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), line); it != std::sregex_iterator(); ++it)
    out[(*it)[1]] = {(*it)[1], (*it)[2], std::stod((*it)[3]), (*it)[4].str().find("dasharray") != std::string::npos};
  return out;
}

}  // namespace

TEST_CASE("cli: render --stress K draws an equilibrium stress as tension and compression", "[cli]") {
  const fs::path d = scratchDir("stress");
  // K4 on the unit square (vertices 1, 2 pinned) and a pendant edge 2-5. Its one stress, by
  // hand: at vertex 1, w12 (1,0) + w14 (0,1) + w13 (1,1) = 0, so the sides carry w and the
  // diagonals -w; the pendant edge carries nothing. Bar 1-2 joins two pins: no equation, its
  // own look.
  const std::string f = (d / "k4.svg").string();
  const Result r = run("render " + example("k4_edge") + " --stress 0 -o " + f);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("stress 0 of 1") != std::string::npos);
  const auto bars = svgBars(readFile(fs::path(f)));
  REQUIRE(bars.size() == 7);
  const SvgBar side = bars.at("bar-2-3"), diagonal = bars.at("bar-1-3");
  CHECK(bars.at("bar-3-4").stroke == side.stroke);
  CHECK(bars.at("bar-1-4").stroke == side.stroke);
  CHECK(bars.at("bar-2-4").stroke == diagonal.stroke);
  const std::set<std::string> colours{side.stroke, diagonal.stroke};
  CHECK(colours == std::set<std::string>{"#CD0000", "#1F77B4"});  // one in tension, one in compression
  for (const char* id : {"bar-2-3", "bar-3-4", "bar-1-4", "bar-2-4", "bar-1-3"})
    CHECK(bars.at(id).width == Approx(side.width).margin(0.01));  // |w| equal: equal widths
  CHECK(bars.at("bar-2-5").width < 0.5 * side.width);  // no stress: thin
  CHECK(bars.at("bar-2-5").stroke == "#CCCCCC");
  CHECK(bars.at("bar-1-2").stroke == "#4682B4");  // between pins: the figure's bar
  // A stress that is not there: a clear refusal, nothing written.
  const std::string g = (d / "none.svg").string();
  const Result none = run("render " + example("square") + " --stress 0 -o " + g);
  CHECK(none.status == 1);  // wrong input, not an output that could not be written
  CHECK(none.err.find("stress 0 ([render] stress, render --stress): the equilibrium stresses at sample 0 span 0 "
                      "dimensions") != std::string::npos);
  CHECK_FALSE(fs::exists(g));
  CHECK(run("render " + example("k4_edge") + " --stress x -o " + g).status != 0);
}

TEST_CASE("cli: edges and vertices in their own look, with their ids in SVG and TikZ", "[cli]") {
  const fs::path d = scratchDir("part_styles");
  const fs::path scene = d / "s.toml";
  const auto write = [&](const std::string& render) {
    std::ofstream(scene) << "[system]\ntype = \"framework\"\nvertices = [[0, 0], [1, 0], [1, 1], [0, 1]]\n"
                            "edges = [[1, 2], [2, 3], [3, 4], [4, 1], [1, 3]]\n\n[render]\n"
                         << render << "\n";
  };
  write("edge_styles = [{edges = [[3, 1]], color = \"red3\", width = \"3pt\", dash = true, label = \"c\"}]\n"
        "vertex_styles = [{vertices = [4], color = \"#00FF00\", size = 80, label = \"P\"}]");
  const std::string svg = (d / "s.svg").string(), tex = (d / "s.tex").string();
  REQUIRE(run("render " + scene.string() + " -o " + svg).status == 0);
  const std::string text = readFile(fs::path(svg));
  const auto bars = svgBars(text);
  REQUIRE(bars.size() == 5);
  CHECK(bars.at("bar-1-3").stroke == "#CD0000");
  CHECK(bars.at("bar-1-3").width == Approx(4));  // 3 pt at 96 px per inch
  CHECK(bars.at("bar-1-3").dashed);
  CHECK(bars.at("bar-1-2").stroke == "#4682B4");
  CHECK_FALSE(bars.at("bar-1-2").dashed);
  CHECK(text.find(">c</text>") != std::string::npos);
  CHECK(std::regex_search(text, std::regex(R"re(<circle class="joint" id="joint-4"[^>]*r="40"[^>]*fill="#00FF00")re")));
  CHECK(text.find(">P</text>") != std::string::npos);
  CHECK(text.find(">4</text>") == std::string::npos);
  REQUIRE(run("render " + scene.string() + " -o " + tex).status == 0);
  CHECK(readFile(fs::path(tex)).find("; % bar-1-3\n") != std::string::npos);
  // Ids stay unique in a filmstrip: the later panels prefix theirs.
  REQUIRE(run("render " + example("square") + " --samples 0,5 -o " + svg).status == 0);
  const std::string strip = readFile(fs::path(svg));
  CHECK(strip.find("id=\"bar-1-2\"") != std::string::npos);
  CHECK(strip.find("id=\"p2-bar-1-2\"") != std::string::npos);

  // Refused at their place: an edge that is not a bar, an unknown key, a vertex out of range.
  const auto refused = [&](const std::string& render, const std::string& message) {
    write(render);
    const Result r = run("render " + scene.string() + " -o " + (d / "x.png").string());
    INFO(render << " -> " << r.err);
    CHECK(r.status == 1);
    CHECK(r.err.find("s.toml:7:") != std::string::npos);
    CHECK(r.err.find(message) != std::string::npos);
  };
  refused("edge_styles = [{edges = [[2, 4]], color = \"red3\"}]", "[2, 4] is not a bar");
  refused("edge_styles = [{edges = [[1, 2]], colour = \"red3\"}]", "unknown key 'colour'");
  refused("vertex_styles = [{vertices = [9]}]", "out of range");
  refused("edge_styles = [{color = \"red3\"}]", "edges");
}

TEST_CASE("cli: a 3D TikZ figure fades its parts through fog styles of its own colours", "[cli]") {
  const fs::path d = scratchDir("tikz_fog");
  const auto tikz = [&](const std::string& args) {
    const std::string tex = (d / "c.tex").string();
    REQUIRE(run("render " + example("coned_cube") + " --set motion.steps=0 -o " + tex + args).status == 0);
    return readFile(fs::path(tex));
  };
  const auto rgb = [](const std::string& t, const std::string& name) {
    std::smatch m;
    REQUIRE(std::regex_search(t, m, std::regex("\\\\definecolor\\{" + name + "\\}\\{RGB\\}\\{([0-9,]+)\\}")));
    return m[1].str();
  };
  const std::string t = tikz(""), flat = tikz(" --set render.fog=0");
  std::smatch m;
  REQUIRE(std::regex_search(t, m, std::regex(R"re(flexure bar/\.style=\{draw=(\w+),)re")));
  const std::string bar = m[1];
  REQUIRE(std::regex_search(t, m, std::regex(R"re(flexure bar fog/\.style=\{draw=(\w+)!#1!(\w+)\})re")));
  CHECK(m[1] == bar);  // the fog style mixes the style's own colour ...
  CHECK(rgb(t, m[2]) == "255,255,255");  // ... with the background
  // Without fog the bars are that colour: the fog style starts from the unfaded colour.
  REQUIRE(std::regex_search(flat, m, std::regex(R"re(flexure bar/\.style=\{draw=(\w+),)re")));
  CHECK(rgb(flat, m[1]) == rgb(t, bar));
  // No bar repeats a colour inline; each keeps 65-100 % of it (fog 0.35 at the far side), more
  // the nearer it is, so the percentages differ.
  CHECK(t.find("\\draw[flexure bar, draw=") == std::string::npos);
  std::set<int> keeps;
  const std::regex faded(R"re(\\draw\[flexure bar(?:, flexure bar fog=(\d+))?\])re");
  int n = 0;
  for (auto it = std::sregex_iterator(t.begin(), t.end(), faded); it != std::sregex_iterator(); ++it, ++n)
    keeps.insert((*it)[1].matched ? std::stoi((*it)[1]) : 100);
  CHECK(n == 19);
  CHECK(keeps.size() >= 4);
  CHECK(*keeps.begin() >= 65);
  CHECK(*keeps.rbegin() <= 100);
}

TEST_CASE("cli: flex arrows are drawn over the bars, in 2D and in 3D", "[cli]") {
  const fs::path d = scratchDir("arrows_on_top");
  for (const std::string name : {"square", "coned_cube"}) {
    const std::string f = (d / (name + ".svg")).string();
    REQUIRE(run("render " + example(name) + " --flex -o " + f).status == 0);
    const std::string t = readFile(fs::path(f));
    INFO(name);
    const size_t first_flex = t.find("class=\"flex\""), last_bar = t.rfind("class=\"bar\"");
    REQUIRE(first_flex != std::string::npos);
    REQUIRE(last_bar != std::string::npos);
    CHECK(first_flex > last_bar);  // painted after every bar (3D: whatever its depth)
  }
}
