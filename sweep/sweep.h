// `flexure sweep`: one job (analyze or track) over a family of systems, in one process, on all
// cores, as JSON Lines: one line per item (in the family's order, whatever the thread count),
// then a summary line. The output file is append-only and resumable: a rerun skips the items
// it already holds; `--slice k/N` runs every N-th item from the k-th (k from 0), and merge()
// joins the N shards into the file a single run writes.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scenes/scene.h"

namespace flexure::sweep {

using Json = nlohmann::ordered_json;

enum class Job { Analyze, Track };
const char* toString(Job job);

struct Slice {
  int k = 0, n = 1;  // this shard: the items whose id is k modulo n
};

struct Options {
  Job job = Job::Analyze;
  int dimension = 2;            // graph families: the realization's dimension
  std::uint64_t seed = 1;       // graph families: every realization's seed derives from it
  int realizations = 1;         // graph families: realizations per graph
  Slice slice;
  int threads = 0;              // 0: every core
  std::string where;            // keep only the items it holds for ("": all)
  bool samples = false;         // track: the samples on each line
  std::vector<std::string> overrides;  // --set KEY=VALUE, on every item
  // --fields: the result fields each line keeps (dotted paths; empty: all). When these and the
  // --where fields are all counts (kCountFields), sweep analyze computes the counts alone.
  std::vector<std::string> fields;
};

// The fields of sweep analyze that the counts give (no bases, no second order): with --fields
// and --where within them, each item costs one factorization.
extern const std::vector<std::string> kCountFields;
// Whether the sweep computes the counts alone.
bool countsOnly(const Options& options);

// One system of a family, in the family's order.
struct Item {
  long long id = 0;     // from 0, over the whole family (a slice keeps its ids)
  std::string input;    // where it comes from, e.g. "graphs.g6:17" (file:line) or a scene file
  Json extra;           // what sets it apart: graph6, realization, realization_seed, parameters
  std::string payload;  // the family's own (a graph6 line, a scene file)
  long long index = 0;  // the family's own (a combination of swept values)
  int line = 0;         // graph streams: the line of the input
};

// A family of systems: a graph6/sparse6 stream, a list or directory of scene files, or a scene
// with a [sweep] table (see openFamily).
class Family {
 public:
  virtual ~Family() = default;
  // The next item, or false at the end. One thread calls it; throws SceneError for input that
  // cannot be read as items at all (a malformed list), never for one bad item.
  virtual bool next(Item& item) = 0;
  // The item's scene; any thread may call it. Throws SceneError (the item's problem).
  virtual scenes::Scene load(const Item& item) const = 0;
};

// The family of INPUT: "-" or a .g6/.s6/.graph6/.sparse6 file (a graph6/sparse6 stream, one
// realization per graph and `realizations`), a directory (its .toml files, recursively, in
// name order), a .toml scene (with a [sweep] table: one item per combination of its values;
// without: one item), or any other file (a list of scene files or catalog names, one per line,
// relative to the list; blank lines and lines starting with # are skipped). `in` is read for
// "-". Throws SceneError.
std::unique_ptr<Family> openFamily(const std::string& input, const Options& options, std::istream* in = nullptr);

// The seed of realization r of graph g (from 0), from the sweep's seed: the same whatever the
// slice or thread count, and a valid [system] seed (below 2^63).
std::uint64_t itemSeed(std::uint64_t seed, long long graph, int realization);

// Counts over item lines, the same for a run and a merge of its shards.
struct Tally {
  long long items = 0;
  std::map<std::string, long long> status;    // ok, error, filtered
  std::map<std::string, long long> verdicts;  // analyze: `rigid`; track: `path_status`
  long long kept = 0;                          // lines with status ok or error
  double item_ms = 0;                          // the items' time_ms, summed
  // --certify: lines with a "certified" field; those where it is true (a proved verdict, a
  // certified path) that this process computed; and those where a line taken over from a file
  // (the output a rerun resumes, the shards a merge joins) says so, which nothing here has
  // verified: a line can be edited to say anything, so these never count as certified.
  long long with_certificate = 0, certified = 0, certified_unverified = 0;
  // `computed`: the line was made by this process now, not read back from a file.
  void add(const Json& line, bool computed);
  Tally& operator+=(const Tally& other);
};

// What the sweep's lines depend on (the summary's "sweep" object; shards differ in "slice").
Json sweepParameters(const std::string& input, const Options& options);
// The summary line's JSON.
Json summaryJson(const Json& parameters, const Tally& tally, double wall_seconds);

struct RunResult {
  Tally tally;             // every item of the output, earlier runs' included
  long long resumed = 0;   // items found done in the output
  long long computed = 0;  // items computed now
  bool complete = false;   // the summary is written
  bool interrupted = false;
};

// Runs the sweep of `family` into `out` ("" or "-": standard output, not resumable).
// `stop` is polled (about every 50 ms): once true no new item starts, the finished ones are
// written in order, and the run returns interrupted (no summary: a rerun continues).
// `progress(done, computed_now)` after each line. Throws SceneError (a bad family or an output
// that holds another sweep), present::OutputError (the output cannot be written).
RunResult run(Family& family, const std::string& input, const Options& options, const std::string& out,
              const std::function<bool()>& stop = {}, const std::function<void(long long)>& progress = {});

// Joins complete shards (each ending with its summary, the same sweep, slices 0..N-1 once
// each) into `out`, written atomically: the item lines in id order, byte for byte, and the
// summary a single run writes. Throws SceneError naming the shard and line.
Tally merge(const std::vector<std::string>& shards, const std::string& out);

// The field names an item line can have for `job` (dotted for nested objects), for --where.
std::vector<std::string> itemFields(Job job);

}  // namespace flexure::sweep
