// The sweep's runner (sweep.h): items computed on a pool of threads, written in order.
#include "sweep/sweep.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <Eigen/Core>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>

#include "pipeline/pipeline.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/report.h"
#include "scenes/json_text.h"
#include "sweep/where.h"

namespace flexure::sweep {

using scenes::SceneError;
using Clock = std::chrono::steady_clock;

const char* toString(Job job) { return job == Job::Analyze ? "analyze" : "track"; }

namespace {
// What every line keeps with --fields: what identifies the item and its outcome.
const char* const kItemFields[] = {"id", "input", "graph6", "realization", "realization_seed", "parameters",
                                   "status", "error", "flexure"};

// Which flexure computed the line (SPEC section 5), with the sweep's seed (each realization's
// own is the line's realization_seed).
Json provenance(std::uint64_t seed) {
  static const Json p = present::provenanceJson();
  Json out = p;
  out["seed"] = seed;
  return out;
}
}  // namespace

// present::countsJson's fields.
const std::vector<std::string> kCountFields = {"title", "scene", "system", "dimension", "vertices", "pinned",
                                               "variables", "equations", "rigidity_rank", "trivial_inf_flexes",
                                               "nontrivial_inf_flexes", "stress_dim", "inf_rigid"};

bool countsOnly(const Options& o) {
  if (o.job != Job::Analyze || o.fields.empty()) return false;
  const auto counted = [](const std::string& f) {
    return std::find(kCountFields.begin(), kCountFields.end(), f) != kCountFields.end() ||
           std::find(std::begin(kItemFields), std::end(kItemFields), f) != std::end(kItemFields);
  };
  if (!std::all_of(o.fields.begin(), o.fields.end(), counted)) return false;
  return o.where.empty() || [&] {
    const Where w(o.where, itemFields(o.job));
    return std::all_of(w.fields().begin(), w.fields().end(), counted);
  }();
}

namespace {

// The fields a filtered item keeps: enough to count it.
const char* const kVerdictFields[] = {"rigid", "inf_rigid", "path_status", "certified"};

// The results of one item as the job writes them (no id, input, status...).
Json jobResult(Job job, const scenes::Scene& scene, bool samples, bool counts_only, const engine::StepCallback& on_step) {
  if (job == Job::Analyze && counts_only) return present::countsJson(scene, pipeline::analyze(scene, true));
  if (job == Job::Analyze) return present::analysisJson(scene, pipeline::analyze(scene, false));
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps, on_step);
  Json path = present::pathJson(scene, m.path, samples);
  // The path's own "status" becomes "path_status": "status" is the item's.
  Json out = Json::object();
  for (auto it = path.begin(); it != path.end(); ++it) out[it.key() == "status" ? "path_status" : it.key()] = *it;
  return out;
}

// One item's line, computed. `stopped`: a track was cut short by `stop` (not to be written).
Json computeItem(const Family& family, const Item& item, const Options& o, const Where* where, bool counts_only,
                 const std::function<bool()>& stop, bool& stopped) {
  const auto t0 = Clock::now();
  Json line = Json::object();
  line["id"] = item.id;
  line["input"] = item.input;
  for (auto it = item.extra.begin(); it != item.extra.end(); ++it) line[it.key()] = *it;
  Json result;
  std::string error;
  try {
    const scenes::Scene scene = family.load(item);
    result = jobResult(o.job, scene, o.samples, counts_only, [&](int, int) {
      if (stop && stop()) stopped = true;
      return !stopped;
    });
  } catch (const SceneError& e) {
    error = e.what();
  } catch (const std::bad_alloc&) {
    error = "out of memory";
  } catch (const std::exception& e) {
    error = e.what();
  }
  line["status"] = error.empty() ? "ok" : "error";
  line["error"] = error.empty() ? Json(nullptr) : Json(error);
  line["flexure"] = provenance(o.seed);
  for (auto it = result.begin(); it != result.end(); ++it)
    if (it.key() != "flexure") line[it.key()] = *it;  // the line is the sweep's: its provenance, its seed
  if (where && error.empty() && !(*where)(line)) {
    Json kept = Json::object();
    for (const char* k : {"id", "input", "graph6", "realization", "realization_seed", "parameters"})
      if (line.contains(k)) kept[k] = line[k];
    kept["status"] = "filtered";
    kept["error"] = nullptr;
    kept["flexure"] = line["flexure"];
    for (const char* k : kVerdictFields)
      if (line.contains(k)) kept[k] = line[k];
    line = std::move(kept);
  }
  if (!o.fields.empty() && line["status"] != "filtered") {
    Json kept = Json::object();
    for (const char* k : kItemFields)
      if (line.contains(k)) kept[k] = line[k];
    for (const std::string& f : o.fields) {
      // A dotted path: the nested value, under its whole path.
      const Json* v = &line;
      for (size_t at = 0; v && at != std::string::npos;) {
        const size_t dot = f.find('.', at);
        const std::string part = f.substr(at, dot == std::string::npos ? std::string::npos : dot - at);
        v = v->is_object() && v->contains(part) ? &(*v)[part] : nullptr;
        at = dot == std::string::npos ? dot : dot + 1;
      }
      if (v) kept[f] = *v;
    }
    line = std::move(kept);
  }
  line["time_ms"] = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return line;
}

std::string lineText(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n"; }

// An output written a line at a time (append-only, so that a rerun can continue it).
class LineWriter {
 public:
  explicit LineWriter(const std::string& path) : path_(path) {
    if (path.empty() || path == "-") {
      fd_ = 1;
      return;
    }
    present::checkReplaceable(path);
    // O_NONBLOCK: a FIFO made since the check fails at once (ENXIO) instead of waiting for a reader.
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0644);
    if (fd_ < 0 && errno == ELOOP) present::checkReplaceable(path);
    if (fd_ < 0) throw present::OutputError("cannot write " + path + ": " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      throw present::OutputError("cannot write " + path + ": it is not a regular file");
    }
    ::fcntl(fd_, F_SETFL, O_APPEND);  // blocking writes from here on
    // One writer per output: two runs appending to one file would both write every item.
    // A file system without locks (Lustre mounted noflock: ENOSYS; ENOLCK, EOPNOTSUPP) writes
    // unlocked, as before: refusing would stop every sweep there. (On NFS a lock held by a node
    // that crashed lasts until the server's lock recovery.)
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0 && errno != ENOSYS && errno != ENOLCK && errno != EOPNOTSUPP) {
      const int e = errno;
      ::close(fd_);
      throw present::OutputError("cannot write " + path + ": " +
                                 (e == EWOULDBLOCK ? std::string("another flexure is writing it (two runs on one "
                                                                     "output would both append every item); wait "
                                                                     "for it to end, or choose another output")
                                                       : std::string(std::strerror(e))));
    }
    own_ = true;
  }
  ~LineWriter() {
    try {
      flush();
    } catch (...) {
    }
    if (own_) ::close(fd_);
  }
  void add(const std::string& line) {
    buf_ += line;
    if (buf_.size() > (1 << 16) || Clock::now() - last_ > std::chrono::milliseconds(200)) flush();
  }
  void flush() {
    size_t at = 0;
    while (at < buf_.size()) {
      const ssize_t n = ::write(fd_, buf_.data() + at, buf_.size() - at);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int e = errno;
        buf_.erase(0, at);
        throw present::OutputError("cannot write " + (own_ ? path_ : std::string("standard output")) + ": " +
                                   std::strerror(e));
      }
      at += static_cast<size_t>(n);
    }
    buf_.clear();
    last_ = Clock::now();
  }

 private:
  std::string path_, buf_;
  int fd_ = -1;
  bool own_ = false;
  Clock::time_point last_ = Clock::now();
};

// What a read keeps of an item line: its id and the fields that a resume compares and a tally
// counts (not the whole report: an output may hold millions of lines).
Json brief(const Json& j) {
  Json b = Json::object();
  for (const char* k : {"id", "input", "realization_seed", "status", "rigid", "path_status", "certified", "time_ms"})
    if (const auto it = j.find(k); it != j.end()) b[k] = *it;
  return b;
}

// The lines of an output or shard, read one at a time: item lines (in increasing id order) and
// the summary, last. SceneError at the file and line for anything else.
class LineReader {
 public:
  LineReader(std::string path, bool allow_partial_tail) : path_(std::move(path)), partial_ok_(allow_partial_tail) {
    in_.open(path_, std::ios::binary);
    if (!in_) throw SceneError(path_, 1, 1, std::string("cannot open: ") + std::strerror(errno));
  }
  // The next item line (its parsed JSON and text), or false at the end or at the summary.
  bool next(Json& item, std::string* text = nullptr) {
    std::string line;
    while (std::getline(in_, line)) {
      ++n_;
      if (in_.eof()) {  // no newline after it: a line cut short by a kill
        if (!partial_ok_) throw SceneError(path_, n_, 1, "the last line is cut short: the shard is incomplete");
        partial_tail_ = true;
        return false;
      }
      if (summary_) throw SceneError(path_, n_, 1, "a line after the summary");
      scenes::checkJsonShape(line, path_, n_);
      Json j;
      try {
        j = Json::parse(line);
      } catch (const std::exception&) {
        throw SceneError(path_, n_, 1, "not a line of a sweep (not JSON)");
      }
      complete_bytes_ += line.size() + 1;
      // The summary line: {"summary": {...}} and, since provenance, "flexure" beside it.
      if (j.is_object() && j.contains("summary") && j["summary"].is_object() &&
          j.size() == 1 + static_cast<size_t>(j.contains("flexure"))) {
        checkSummary(j["summary"]);
        summary_ = std::move(j["summary"]);
        continue;
      }
      if (!j.is_object() || !j.contains("id") || !j["id"].is_number_integer() || !j.contains("status"))
        throw SceneError(path_, n_, 1, "not a line of a sweep (neither an item with id and status nor the summary)");
      checkItem(j);
      const long long id = j["id"].get<long long>();
      if (id <= last_id_) throw SceneError(path_, n_, 1, "the item ids are not increasing: not the output of one sweep");
      last_id_ = id;
      item = std::move(j);
      if (text) *text = line + "\n";
      return true;
    }
    if (in_.bad()) throw SceneError(path_, n_, 1, "cannot read");
    return false;
  }
  const std::optional<Json>& summary() const { return summary_; }
  long long summaryItems() const { return (*summary_)["items"].get<long long>(); }
  std::string summarySlice() const {
    const Json& sw = (*summary_)["sweep"];
    return sw.contains("slice") ? sw["slice"].get<std::string>() : "0/1";
  }
  double summaryWall() const { return summary_->value("wall_time_s", 0.0); }
  bool partialTail() const { return partial_tail_; }
  std::uint64_t completeBytes() const { return complete_bytes_; }  // up to the end of the last whole line
  int line() const { return n_; }

 private:
  // The fields the sweep reads back, of the types it wrote (a forged or damaged line is
  // refused at its line, never read as something else).
  [[noreturn]] void wrongType(const std::string& field, const char* needs) const {
    throw SceneError(path_, n_, 1, "\"" + field + "\" is not " + needs + ": not a line flexure wrote");
  }
  void checkItem(const Json& j) const {
    if (j["id"].get<long long>() < 0) wrongType("id", "a nonnegative integer");
    if (!j["status"].is_string()) wrongType("status", "a string");
    const std::string st = j["status"].get<std::string>();
    if (st != "ok" && st != "error" && st != "filtered") wrongType("status", "ok, error or filtered");
    if (j.contains("input") && !j["input"].is_string()) wrongType("input", "a string");
    if (j.contains("realization_seed") && !j["realization_seed"].is_number_integer())
      wrongType("realization_seed", "an integer");
    for (const char* k : {"rigid", "path_status"})
      if (j.contains(k) && !j[k].is_string() && !j[k].is_null()) wrongType(k, "a string");
    if (j.contains("time_ms") && !j["time_ms"].is_number()) wrongType("time_ms", "a number");
    if (j.contains("certified") && !j["certified"].is_boolean()) wrongType("certified", "true or false");
  }
  void checkSummary(const Json& s) const {
    if (!s.contains("sweep") || !s["sweep"].is_object()) wrongType("summary.sweep", "an object");
    if (s["sweep"].contains("slice") && !s["sweep"]["slice"].is_string()) wrongType("summary.sweep.slice", "a string k/N");
    if (!s.contains("items") || !s["items"].is_number_integer() || s["items"].get<long long>() < 0)
      wrongType("summary.items", "a nonnegative integer");
    if (s.contains("wall_time_s") && !s["wall_time_s"].is_number()) wrongType("summary.wall_time_s", "a number");
  }

  std::string path_;
  bool partial_ok_;
  std::ifstream in_;
  int n_ = 0;
  long long last_id_ = -1;
  std::optional<Json> summary_;
  bool partial_tail_ = false;
  std::uint64_t complete_bytes_ = 0;
};

Json withoutSlice(Json p) {
  p.erase("slice");
  return p;
}

}  // namespace

void Tally::add(const Json& line, bool computed) {
  ++items;
  const std::string status = line.value("status", "");
  ++this->status[status];
  if (status != "filtered") ++kept;
  for (const char* k : {"rigid", "path_status"})
    if (const auto it = line.find(k); it != line.end() && it->is_string()) ++verdicts[it->get<std::string>()];
  if (const auto it = line.find("time_ms"); it != line.end() && it->is_number()) item_ms += it->get<double>();
  if (const auto it = line.find("certified"); it != line.end() && it->is_boolean()) {
    ++with_certificate;
    if (it->get<bool>()) ++(computed ? certified : certified_unverified);
  }
}

Tally& Tally::operator+=(const Tally& o) {
  items += o.items;
  kept += o.kept;
  item_ms += o.item_ms;
  with_certificate += o.with_certificate;
  certified += o.certified;
  certified_unverified += o.certified_unverified;
  for (const auto& [k, n] : o.status) status[k] += n;
  for (const auto& [k, n] : o.verdicts) verdicts[k] += n;
  return *this;
}

Json sweepParameters(const std::string& input, const Options& o) {
  Json p = Json::object();
  p["job"] = toString(o.job);
  p["input"] = input;
  p["dimension"] = o.dimension;
  p["seed"] = o.seed;
  p["realizations"] = o.realizations;
  p["where"] = o.where.empty() ? Json(nullptr) : Json(o.where);
  if (!o.fields.empty()) p["fields"] = o.fields;
  if (o.job == Job::Track) p["samples"] = o.samples;
  p["set"] = o.overrides;
  if (o.slice.n > 1) p["slice"] = std::to_string(o.slice.k) + "/" + std::to_string(o.slice.n);
  return p;
}

Json summaryJson(const Json& parameters, const Tally& t, double wall_seconds) {
  Json s = Json::object();
  s["sweep"] = parameters;
  s["items"] = t.items;
  s["kept"] = t.kept;
  Json status = Json::object();
  for (const char* k : {"ok", "error", "filtered"}) status[k] = t.status.count(k) ? t.status.at(k) : 0;
  s["status"] = status;
  Json verdicts = Json::object();
  for (const auto& [k, v] : t.verdicts) verdicts[k] = v;
  s["verdicts"] = verdicts;
  // --certify: how many items have a proved verdict (analyze) or a certified path (track) that
  // this run computed, and how many lines taken over from a file (a resumed output, a merge's
  // shards) claim one, unverified.
  if (t.with_certificate > 0) {
    s["certified"] = t.certified;
    s["certified_unverified"] = t.certified_unverified;
  }
  s["items_time_s"] = t.item_ms / 1000.0;
  s["wall_time_s"] = wall_seconds;
  Json out = Json::object();
  out["summary"] = std::move(s);
  out["flexure"] = parameters.contains("seed") ? provenance(parameters["seed"].get<std::uint64_t>())
                                               : Json(present::provenanceJson());
  return out;
}

std::vector<std::string> itemFields(Job job) {
  // The fields of real results: a rigid triangle and a flexible 4-cycle with a stressed
  // diagonal pair, analysed or tracked, certified (--certify's fields); plus the sweep's own.
  const char* const texts[] = {R"(title = "t"
[system]
type = "framework"
vertices = [[0, 0], [1, 0], [0, 1]]
edges = [[1, 2], [2, 3], [1, 3]]
[analysis]
certify = true
[motion]
steps = 1
certify = true
)",
                               R"(title = "q"
[system]
type = "framework"
vertices = [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0]]
edges = [[1, 2], [2, 3], [3, 4], [4, 1], [2, 5]]
pinned = [1, 2]
[analysis]
certify = true
[motion]
steps = 1
certify = true
)"};
  Json line = Json::object();
  for (const char* k : {"id", "input", "graph6", "realization", "realization_seed", "parameters", "status", "error", "time_ms"})
    line[k] = nullptr;
  for (const char* text : texts) {
    const scenes::Scene scene = scenes::loadSceneFromString(text, "fields");
    const Json r = jobResult(job, scene, job == Job::Track, false, {});
    for (auto it = r.begin(); it != r.end(); ++it) line[it.key()] = *it;
  }
  std::vector<std::string> fields = fieldPaths(line);
  if (job == Job::Analyze)
    for (const char* k : {"nontrivial_flex_basis", "equation_labels", "stress_basis", "second_order.blocking_stress"})
      if (std::find(fields.begin(), fields.end(), k) == fields.end()) fields.push_back(k);
  return fields;
}

RunResult run(Family& family, const std::string& input, const Options& o, const std::string& out,
              const std::function<bool()>& stop, const std::function<void(long long)>& progress) {
  const auto t0 = Clock::now();
  const Json params = sweepParameters(input, o);
  std::optional<Where> where;
  if (!o.where.empty()) where.emplace(o.where, itemFields(o.job));
  const bool counts_only = countsOnly(o);
  RunResult result;

  // What the output holds already (a regular file only: not a FIFO or a terminal).
  std::vector<Json> done;  // brief() of each item line
  std::optional<std::uint64_t> cut_to;  // a partial last line to cut off, once the lines are known to match
  const bool to_file = !out.empty() && out != "-";
  LineWriter writer(out);  // opened (and locked) before the old lines are read
  std::error_code ec;
  if (to_file && std::filesystem::is_regular_file(out, ec) && std::filesystem::file_size(out, ec) > 0) {
    LineReader old(out, true);
    Json j;
    while (old.next(j)) done.push_back(brief(j));
    if (old.summary()) {
      const Json& sw = (*old.summary())["sweep"];
      if (sw != params)
        throw SceneError(out, old.line(), 1,
                         "holds the summary of another sweep (" + sw.dump().substr(0, 300) + "): choose another output or remove it");
      for (const Json& d : done) result.tally.add(d, false);
      result.resumed = static_cast<long long>(done.size());
      result.complete = true;
      return result;
    }
    if (old.partialTail()) cut_to = old.completeBytes();
  }
  for (const Json& d : done) result.tally.add(d, false);  // taken over: certificates unverified
  result.resumed = static_cast<long long>(done.size());

  // The window of items in flight: claimed by the workers in order, written in order.
  struct Slot {
    Item item;
    Tally tally;       // the line's counts (the worker's: the line is made and freed there)
    std::string text;  // the line as written (dumped by the worker)
    bool done = false, stopped = false;
  };
  std::deque<Slot> window;
  std::mutex m;
  std::condition_variable work, finished;
  size_t claimed = 0;  // slots handed out, counted from the window's front
  bool quit = false, stopping = false;
  std::atomic<bool> stop_flag{false};
  const std::function<bool()> stop_now = [&] { return stop_flag.load(); };
  int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const size_t capacity = static_cast<size_t>(threads) * 32;
  // The main thread wakes to write a batch: half the window done from its front (or all of it),
  // not every small item (a wake-up per item was a quarter of a sweep's CPU on 1,454 graphs of 8
  // vertices); after an item of 5 ms or more, at once (`wake`).
  bool wake = false;
  auto batchReady = [&] {
    size_t prefix = 0;
    while (prefix < window.size() && window[prefix].done) ++prefix;
    return prefix > 0 && (wake || prefix == window.size() || prefix >= capacity / 2);
  };

  auto worker = [&] {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      work.wait(lock, [&] { return quit || (!stopping && claimed < window.size()); });
      if (quit) return;
      Slot& s = window[claimed++];
      lock.unlock();
      bool stopped = false;
      Json line;
      std::string text;
      const auto started = Clock::now();
      try {
        line = computeItem(family, s.item, o, where ? &*where : nullptr, counts_only, stop_now, stopped);
        text = lineText(line);
      } catch (...) {  // out of memory while writing the line: the item fails, the sweep goes on
        line = Json{{"id", s.item.id}, {"input", s.item.input}, {"status", "error"}, {"error", "out of memory"}};
        text = lineText(line);
      }
      Tally tally;
      tally.add(line, true);
      line = Json();
      lock.lock();
      s.tally = std::move(tally);
      s.text = std::move(text);
      s.stopped = stopped;
      s.done = true;
      if (Clock::now() - started >= std::chrono::milliseconds(5)) wake = true;
      if (stopping || batchReady()) finished.notify_all();
    }
  };

  size_t next_done = 0;  // the next line of `done` the family's items must match
  bool exhausted = false;
  // The next item of this slice that the output does not hold.
  auto nextItem = [&](Item& item) {
    while (family.next(item)) {
      if (item.id % o.slice.n != o.slice.k) continue;
      if (next_done < done.size()) {
        const Json& d = done[next_done];
        if (d["id"].get<long long>() != item.id || d.value("input", "") != item.input ||
            (item.extra.contains("realization_seed") && d.value("realization_seed", Json()) != item.extra["realization_seed"]))
          throw SceneError(out, static_cast<int>(next_done) + 1, 1,
                           "holds item " + d["id"].dump() + " of another sweep (" + d.value("input", "") +
                               "): choose another output or remove it");
        ++next_done;
        continue;
      }
      return true;
    }
    return false;
  };
  auto refill = [&] {
    while (!exhausted && !stopping && window.size() < capacity) {
      Item item;
      if (!nextItem(item)) {
        exhausted = true;
        break;
      }
      std::lock_guard<std::mutex> lock(m);
      window.push_back(Slot{std::move(item), Tally(), std::string(), false, false});
      work.notify_one();
    }
  };

  // Eigen sets up its cache sizes (static, for the blocking of products) on first use; done
  // here, before the threads, they are only read afterwards (helgrind saw the race).
  Eigen::initParallel();
  std::vector<std::thread> pool;
  auto shutdown = [&] {
    {
      std::lock_guard<std::mutex> lock(m);
      quit = true;
      work.notify_all();
    }
    for (auto& t : pool) t.join();
    pool.clear();
  };
  try {
    refill();  // passes over (and compares) every item the output holds
    if (exhausted && next_done < done.size())
      throw SceneError(out, static_cast<int>(next_done) + 1, 1,
                       "holds items this sweep does not have: it is the output of another sweep");
    if (cut_to) {
      writer.flush();
      std::filesystem::resize_file(out, *cut_to, ec);
      if (ec) throw present::OutputError("cannot cut the partial last line of " + out + ": " + ec.message());
    }
    for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
    for (;;) {
      std::unique_lock<std::mutex> lock(m);
      if (window.empty()) break;
      finished.wait_for(lock, std::chrono::milliseconds(50), batchReady);
      wake = false;
      if (!stopping && stop && stop()) {
        stopping = true;
        stop_flag = true;
      }
      if (stopping) {
        // Wait for the items in flight, then write the finished ones in order.
        finished.wait(lock, [&] {
          for (size_t i = 0; i < claimed; ++i)
            if (!window[i].done) return false;
          return true;
        });
        while (!window.empty() && window.front().done && !window.front().stopped) {
          Slot s = std::move(window.front());
          window.pop_front();
          --claimed;
          result.tally += s.tally;
          ++result.computed;
          writer.add(s.text);
        }
        result.interrupted = true;
        break;
      }
      while (!window.empty() && window.front().done) {
        Slot s = std::move(window.front());
        window.pop_front();
        --claimed;
        lock.unlock();
        result.tally += s.tally;
        ++result.computed;
        writer.add(s.text);
        if (progress) progress(result.tally.items);
        lock.lock();
      }
      lock.unlock();
      refill();
    }
  } catch (...) {
    shutdown();
    throw;
  }
  shutdown();
  if (!result.interrupted) {
    writer.add(lineText(summaryJson(params, result.tally, std::chrono::duration<double>(Clock::now() - t0).count())));
    result.complete = true;
  }
  writer.flush();
  return result;
}

namespace {

// One shard's lines, read in turn by the merge. With many shards (a Slurm array of 50,000
// tasks) not every file can stay open: then each read reopens the file where it stopped and
// takes a block of at least 4 KB, so that a file is opened about once per block, not per line.
class ShardCursor {
 public:
  ShardCursor(std::string path, bool keep_open) : path_(std::move(path)), keep_open_(keep_open) {}
  std::string next() {
    size_t newline;
    while ((newline = pending_.find('\n', taken_)) == std::string::npos) {
      pending_.erase(0, taken_);
      taken_ = 0;
      if (!in_.is_open()) {
        in_.clear();
        in_.open(path_, std::ios::binary);
        in_.seekg(static_cast<std::streamoff>(read_));
      }
      char block[4096];
      in_.read(block, sizeof block);
      const std::streamsize n = in_.gcount();
      if (n <= 0) throw SceneError(path_, line_ + 1, 1, "changed while it was being merged");
      pending_.append(block, static_cast<size_t>(n));
      read_ += static_cast<std::uint64_t>(n);
      if (!keep_open_) in_.close();
    }
    std::string line = pending_.substr(taken_, newline + 1 - taken_);
    taken_ = newline + 1;
    ++line_;
    return line;
  }

 private:
  std::string path_;
  bool keep_open_;
  std::ifstream in_;
  std::string pending_;     // read, not yet handed out from taken_ on
  size_t taken_ = 0;
  std::uint64_t read_ = 0;  // bytes of the file read so far
  int line_ = 0;
};

// Files this process may keep open: the soft limit raised to the hard one (Slurm arrays have
// thousands of shards; the default soft limit is often 1024).
rlim_t openFileLimit() {
  rlimit r{};
  if (::getrlimit(RLIMIT_NOFILE, &r) != 0) return 256;
  if (r.rlim_cur < r.rlim_max) {
    rlimit raised = r;
    raised.rlim_cur = r.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) r = raised;
  }
  return r.rlim_cur;
}

}  // namespace

Tally merge(const std::vector<std::string>& shards, const std::string& out) {
  if (shards.empty()) throw SceneError("merge", 1, 1, "no shard to merge");
  // First pass: every shard whole, with its summary, of one sweep, the slices once each, and
  // every item there: shard k of N holds items k, k + N, k + 2N... without a gap, as many as its
  // summary counts and as a sweep of all the shards' items gives it.
  std::optional<Json> params;
  // The slices by k (their shard and item count): a map, not a vector of N, so that a forged
  // N (0/2000000000) allocates nothing.
  std::map<long long, std::pair<size_t, long long>> slices;
  long long n = 0;  // the sweep's number of slices, from the first shard
  double wall = 0;
  Tally t;
  for (size_t s = 0; s < shards.size(); ++s) {
    const std::string& shard = shards[s];
    LineReader r(shard, false);
    Json j;
    std::vector<long long> ids;
    Tally own;
    while (r.next(j)) {
      ids.push_back(j["id"].get<long long>());
      own.add(brief(j), false);  // a shard's certificates are claims, not verified here
    }
    if (!r.summary()) throw SceneError(shard, r.line() + 1, 1, "has no summary: the shard is incomplete (rerun its slice)");
    const std::string slice = r.summarySlice();
    long long k = -1, count = 0;
    char rest = 0;
    if (std::sscanf(slice.c_str(), "%lld/%lld%c", &k, &count, &rest) != 2 || count < 1 || k < 0 || k >= count)
      throw SceneError(shard, r.line(), 1, "the summary's slice '" + slice.substr(0, 40) + "' is not k/N");
    if (!params) {
      params = withoutSlice((*r.summary())["sweep"]);
      n = count;
    } else if (withoutSlice((*r.summary())["sweep"]) != *params || count != n) {
      throw SceneError(shard, r.line(), 1,
                       "is a shard of another sweep than " + shards[0] +
                           (count != n ? " (slice " + slice + ", where that one is of " + std::to_string(n) + ")" : ""));
    }
    if (slices.count(k)) throw SceneError(shard, r.line(), 1, "slice " + slice + " is given twice");
    if (r.summaryItems() != static_cast<long long>(ids.size()))
      throw SceneError(shard, r.line(), 1,
                       "its summary counts " + std::to_string(r.summaryItems()) + " items, but it has " +
                           std::to_string(ids.size()) + " item lines: lines were lost (rerun its slice)");
    for (size_t i = 0; i < ids.size(); ++i)
      if (ids[i] != k + static_cast<long long>(i) * n)
        throw SceneError(shard, static_cast<int>(i) + 1, 1,
                         "item " + std::to_string(ids[i]) + " where slice " + slice + " has item " +
                             std::to_string(k + static_cast<long long>(i) * n) +
                             ": lines were lost, or its summary's slice is not its own (rerun its slice)");
    slices[k] = {s, static_cast<long long>(ids.size())};
    wall = std::max(wall, r.summaryWall());
    t += own;
  }
  if (static_cast<long long>(slices.size()) != n) {
    long long missing = 0;
    while (slices.count(missing)) ++missing;
    throw SceneError(shards[0], 1, 1,
                     "slice " + std::to_string(missing) + "/" + std::to_string(n) + " is missing: the sweep has " +
                         std::to_string(n) + " slices, " + std::to_string(slices.size()) + " shard" +
                         (slices.size() == 1 ? " is" : "s are") + " given");
  }
  const long long total = t.items;
  for (const auto& [k, slice] : slices) {
    const long long expected = total > k ? (total - k + n - 1) / n : 0;
    if (slice.second != expected)
      throw SceneError(shards[slice.first], 1, 1,
                       "holds " + std::to_string(slice.second) + " items, where a sweep of " + std::to_string(total) +
                           " items has " + std::to_string(expected) + " in slice " + std::to_string(k) + "/" +
                           std::to_string(n) + ": lines were lost (rerun its slice)");
  }
  // Second pass: the item lines in id order (round by round over the slices), byte for byte.
  present::TemporaryOutput file(out);
  std::vector<ShardCursor> cursors;
  cursors.reserve(static_cast<size_t>(n));
  const bool keep_open = static_cast<double>(n) + 64 <= static_cast<double>(openFileLimit());
  for (const auto& [k, slice] : slices) cursors.emplace_back(shards[slice.first], keep_open);
  std::string buf;
  for (long long id = 0; id < total; ++id) {
    buf += cursors[static_cast<size_t>(id % n)].next();
    if (buf.size() > (1 << 20)) file.write(buf), buf.clear();
  }
  buf += lineText(summaryJson(*params, t, wall));
  file.write(buf);
  file.commit();
  return t;
}

}  // namespace flexure::sweep
