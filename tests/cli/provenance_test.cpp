// Which flexure made an output (SPEC section 5, "Provenance"), and the catalog as a place to
// start from: `catalog NAME` prints an entry's scene, a mistyped name gets "did you mean", a
// catalog's flex direction gives way to a contraction.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "cli_common.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace flexure_cli_test;

namespace {

// The provenance object of a JSON output: its version is `flexure --version`'s, its commit a
// commit of this repository (or "unknown" outside a git checkout), its command the words given.
void checkProvenance(const json& f, const std::vector<std::string>& command) {
  REQUIRE(f.is_object());
  CHECK(run("--version").out == "flexure " + f.at("version").get<std::string>() + "\n");
  const std::string commit = f.at("commit");
  INFO(commit);
  CHECK(std::regex_match(commit, std::regex("[0-9a-f]{12}(-dirty)?|unknown")));
  if (commit != "unknown" && fs::exists(fs::path(FLEXURE_SOURCE_DIR) / ".git"))
    CHECK(shellOutput("git -C " FLEXURE_SOURCE_DIR " cat-file -t " + commit.substr(0, 12) + " 2>&1") == "commit\n");
  CHECK_FALSE(f.at("build_type").get<std::string>().empty());
  CHECK(f.at("command") == json(command));
}

}  // namespace

TEST_CASE("cli: every JSON output and every figure says which flexure made it, and by which command", "[cli]") {
  const fs::path d = scratchDir("provenance");
  const std::string bin = FLEXURE_BINARY, square = example("square");
  const Result a = run("analyze " + square + " --json");
  REQUIRE(a.status == 0);
  const json analysis = json::parse(a.out);
  checkProvenance(analysis.at("flexure"), {bin, "analyze", square, "--json"});
  const std::string commit = analysis["flexure"]["commit"], version = analysis["flexure"]["version"];
  const std::string creator =
      "flexure " + version + " (commit " + commit + ", " + analysis["flexure"]["build_type"].get<std::string>() + ")";

  const std::string p = (d / "p.json").string();
  REQUIRE(run("track " + square + " --quiet --set motion.steps=3 -o " + p).status == 0);
  checkProvenance(json::parse(readFile(p)).at("flexure"), {bin, "track", square, "--quiet", "--set", "motion.steps=3", "-o", p});
  // The seed the randomness flowed from: the scene's, as given.
  REQUIRE(run("track " + square + " --quiet --set motion.steps=3 --set motion.seed=77 -o " + p).status == 0);
  CHECK(json::parse(readFile(p)).at("flexure").at("seed") == 77);
  CHECK(json::parse(readFile(p)).at("seed") == 77);
  const Result seeded = run("analyze " + square + " --json --set analysis.seed=78");
  REQUIRE(seeded.status == 0);
  CHECK(json::parse(seeded.out).at("flexure").at("seed") == 78);

  // A sweep: every item line and the summary line.
  std::ofstream(d / "g.g6") << "C~\nCr\n";
  const Result s = run("sweep analyze " + (d / "g.g6").string() + " --threads 1");
  REQUIRE(s.status == 0);
  std::istringstream lines(s.out);
  int n = 0;
  for (std::string line; std::getline(lines, line); ++n)  // the summary's is beside it
    checkProvenance(json::parse(line).at("flexure"), {bin, "sweep", "analyze", (d / "g.g6").string(), "--threads", "1"});
  CHECK(n == 3);
  const Result seeded_sweep = run("sweep analyze " + (d / "g.g6").string() + " --threads 1 --seed 79");
  REQUIRE(seeded_sweep.status == 0);
  std::istringstream seeded_lines(seeded_sweep.out);
  for (std::string line; std::getline(seeded_lines, line);) CHECK(json::parse(line).at("flexure").at("seed") == 79);
  // With --fields (counts alone) and on lines --where filters out, too.
  const Result f = run("sweep analyze " + (d / "g.g6").string() + " --fields rigidity_rank --where \"inf_rigid\"");
  REQUIRE(f.status == 0);
  std::istringstream flines(f.out);
  for (std::string line; std::getline(flines, line);) CHECK(json::parse(line).at("flexure").at("commit") == commit);

  // The figures: PNG (a tEXt chunk "Software"), SVG (<metadata>), PDF (Creator), TikZ (a comment).
  for (const char* ext : {"png", "svg", "pdf", "tex"}) {
    const std::string out = (d / (std::string("f.") + ext)).string();
    REQUIRE(run("render " + square + " --quiet -o " + out).status == 0);
    const std::string bytes = readFile(out);
    INFO(ext);
    if (std::string(ext) == "png") CHECK_THAT(bytes, Catch::Contains(std::string("tEXtSoftware") + '\0' + creator));
    if (std::string(ext) == "svg") CHECK_THAT(bytes, Catch::Contains("<metadata>" + creator + "</metadata>"));
    if (std::string(ext) == "pdf") {  // a PDF text string in UTF-16BE, as cairo writes it
      std::string utf16 = "FEFF";
      char hex[8];
      for (const unsigned char c : creator) std::snprintf(hex, sizeof hex, "00%02X", c), utf16 += hex;
      CHECK_THAT(bytes, Catch::Contains("/Creator <" + utf16 + ">"));
    }
    if (std::string(ext) == "tex") CHECK_THAT(bytes, Catch::Contains("\n% " + creator + "\n"));
  }
  fs::remove_all(d);
}

TEST_CASE("cli: catalog NAME prints the entry's scene, a mistyped name gets the closest one", "[cli]") {
  const Result cube = run("catalog cube");
  REQUIRE(cube.status == 0);
  CHECK(cube.out == readFile(example("cube")));
  CHECK(run("catalog catalog:cube").out == cube.out);
  // What it prints is a scene: analysed as it is, the same report as the entry's.
  const fs::path d = scratchDir("catalog_name");
  std::ofstream(d / "my_cube.toml") << cube.out;
  const json mine = json::parse(run("analyze " + (d / "my_cube.toml").string() + " --json").out);
  const json entry = json::parse(run("analyze cube --json").out);
  for (const char* k : {"rigidity_rank", "nontrivial_inf_flexes", "stress_dim", "rigid"}) CHECK(mine.at(k) == entry.at(k));
  const Result typo = run("catalog cub");
  CHECK(typo.status == 1);
  CHECK(typo.out.empty());
  CHECK_THAT(typo.err, Catch::StartsWith("flexure: unknown catalog name 'cub' (did you mean 'cube'?)"));
  const Result far = run("catalog zzzzzzzzzzzzzzzzzzzz");
  CHECK(far.status == 1);
  CHECK_THAT(far.err, Catch::Contains("see `flexure catalog`: ") && Catch::Contains("double_watt"));
  CHECK(run("catalog cube k24").status == 1);
  // The same suggestion where a scene argument is neither a file nor an entry, and in a scene.
  CHECK_THAT(run("analyze dobule_watt").err, Catch::Contains("did you mean 'double_watt'?"));
  std::ofstream(d / "c.toml") << "[system]\ntype = \"catalog\"\nname = \"bricard_octahedorn\"\n";
  const Result inner = run("analyze " + (d / "c.toml").string());
  CHECK(inner.status == 1);
  CHECK_THAT(inner.err, Catch::Contains("c.toml:3:8") && Catch::Contains("did you mean 'bricard_octahedron'?"));
  fs::remove_all(d);
}

TEST_CASE("cli: a catalog entry's flex gives way to a contraction, and motion.flex=auto clears it", "[cli]") {
  // The cube's scene follows flex = [1,1,1]: contracting an edge as well is refused, at the
  // flex; --set motion.flex=auto clears it (the catalog entry and its file alike).
  const std::string contract = " --quiet --set motion.contract_edge=[1,2] --set motion.target_length=0.9 --set motion.steps=5";
  const Result over = run("track cube" + contract);
  CHECK(over.status == 1);
  CHECK_THAT(over.err, Catch::Contains("catalog:cube:") && Catch::Contains("flex does not apply to an edge contraction"));
  for (const std::string& scene : {std::string("cube"), example("cube")}) {
    const Result cleared = run("track " + scene + contract + " --set motion.flex=auto");
    INFO(cleared.err);
    CHECK(cleared.status != 1);
    CHECK(json::parse(cleared.out).at("steps_requested") == 5);
  }
  // A scene over the entry that contracts an edge: the entry's flex is not taken.
  const fs::path d = scratchDir("catalog_flex");
  std::ofstream(d / "c.toml") << "[system]\ntype = \"catalog\"\nname = \"cube\"\n[motion]\ncontract_edge = [1, 2]\n"
                                 "target_length = 0.9\nsteps = 5\n";
  const Result scene = run("track --quiet " + (d / "c.toml").string());
  INFO(scene.err);
  CHECK(scene.status != 1);
  fs::remove_all(d);
}
