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
#include <regex>
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
  for (const std::string& w : {"16cm", "8cm"}) {
    const std::vector<double> sizes = captionSizes("--set render.width=" + w + " --set render.height=3cm");
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
  refused("width = \"8cm\"\nheight = 600", "height must be a length too", 8);
  refused("caption = \"t = {time}\"", "unknown field {time}");
  refused("font_size = \"900pt\"", "font_size is");
}
