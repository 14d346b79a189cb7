// The sweep's runner (sweep.h): items computed on a pool of threads, written in order.
#include "sweep/sweep.h"

#include <fcntl.h>
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
#include "sweep/where.h"

namespace flexure::sweep {

using scenes::SceneError;
using Clock = std::chrono::steady_clock;

const char* toString(Job job) { return job == Job::Analyze ? "analyze" : "track"; }

namespace {

// The fields a filtered item keeps: enough to count it.
const char* const kVerdictFields[] = {"rigid", "inf_rigid", "path_status"};

// The results of one item as the job writes them (no id, input, status...).
Json jobResult(Job job, const scenes::Scene& scene, bool samples, const engine::StepCallback& on_step) {
  if (job == Job::Analyze) return present::analysisJson(scene, pipeline::analyze(scene));
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps, on_step);
  Json path = present::pathJson(scene, m.path, samples);
  // The path's own "status" becomes "path_status": "status" is the item's.
  Json out = Json::object();
  for (auto it = path.begin(); it != path.end(); ++it) out[it.key() == "status" ? "path_status" : it.key()] = *it;
  return out;
}

// One item's line, computed. `stopped`: a track was cut short by `stop` (not to be written).
Json computeItem(const Family& family, const Item& item, const Options& o, const Where* where,
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
    result = jobResult(o.job, scene, o.samples, [&](int, int) {
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
  for (auto it = result.begin(); it != result.end(); ++it) line[it.key()] = *it;
  if (where && error.empty() && !(*where)(line)) {
    Json kept = Json::object();
    for (const char* k : {"id", "input", "graph6", "realization", "realization_seed", "parameters"})
      if (line.contains(k)) kept[k] = line[k];
    kept["status"] = "filtered";
    kept["error"] = nullptr;
    for (const char* k : kVerdictFields)
      if (line.contains(k)) kept[k] = line[k];
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
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd_ < 0) throw present::OutputError("cannot write " + path + ": " + std::strerror(errno));
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

// The lines of an output or shard: item lines (parsed, with their text) and the summary.
struct ReadLines {
  std::vector<std::pair<Json, std::string>> items;
  std::optional<Json> summary;
  std::uint64_t complete_bytes = 0;  // up to the end of the last whole line
  bool partial_tail = false;          // a last line without its newline
};

ReadLines readLines(const std::string& path, bool allow_partial_tail) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, 1, 1, std::string("cannot open: ") + std::strerror(errno));
  ReadLines out;
  std::string text;
  int n = 0;
  while (std::getline(in, text)) {
    ++n;
    if (in.eof()) {  // no newline after it: a line cut short by a kill
      if (!allow_partial_tail) throw SceneError(path, n, 1, "the last line is cut short: the shard is incomplete");
      out.partial_tail = true;
      break;
    }
    if (out.summary) throw SceneError(path, n, 1, "a line after the summary");
    Json j;
    try {
      j = Json::parse(text);
    } catch (const std::exception&) {
      throw SceneError(path, n, 1, "not a line of a sweep (not JSON)");
    }
    if (j.is_object() && j.size() == 1 && j.contains("summary") && j["summary"].is_object()) {
      out.summary = j["summary"];
    } else if (j.is_object() && j.contains("id") && j["id"].is_number_integer() && j.contains("status")) {
      if (!out.items.empty() && j["id"].get<long long>() <= out.items.back().first["id"].get<long long>())
        throw SceneError(path, n, 1, "the item ids are not increasing: not the output of one sweep");
      out.items.emplace_back(std::move(j), text + "\n");
    } else {
      throw SceneError(path, n, 1, "not a line of a sweep (neither an item with id and status nor the summary)");
    }
    out.complete_bytes += text.size() + 1;
  }
  if (in.bad()) throw SceneError(path, n, 1, "cannot read");
  return out;
}

Json withoutSlice(Json p) {
  p.erase("slice");
  return p;
}

}  // namespace

void Tally::add(const Json& line) {
  ++items;
  const std::string status = line.value("status", "");
  ++this->status[status];
  if (status != "filtered") ++kept;
  for (const char* k : {"rigid", "path_status"})
    if (const auto it = line.find(k); it != line.end() && it->is_string()) ++verdicts[it->get<std::string>()];
  if (const auto it = line.find("time_ms"); it != line.end() && it->is_number()) item_ms += it->get<double>();
}

Json sweepParameters(const std::string& input, const Options& o) {
  Json p = Json::object();
  p["job"] = toString(o.job);
  p["input"] = input;
  p["dimension"] = o.dimension;
  p["seed"] = o.seed;
  p["realizations"] = o.realizations;
  p["where"] = o.where.empty() ? Json(nullptr) : Json(o.where);
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
  s["items_time_s"] = t.item_ms / 1000.0;
  s["wall_time_s"] = wall_seconds;
  Json out = Json::object();
  out["summary"] = std::move(s);
  return out;
}

std::vector<std::string> itemFields(Job job) {
  // The fields of real results: a rigid triangle and a flexible 4-cycle with a stressed
  // diagonal pair, analysed or tracked; plus the sweep's own.
  const char* const texts[] = {R"(title = "t"
[system]
type = "framework"
vertices = [[0, 0], [1, 0], [0, 1]]
edges = [[1, 2], [2, 3], [1, 3]]
[motion]
steps = 1
)",
                               R"(title = "q"
[system]
type = "framework"
vertices = [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0]]
edges = [[1, 2], [2, 3], [3, 4], [4, 1], [2, 5]]
pinned = [1, 2]
[motion]
steps = 1
)"};
  Json line = Json::object();
  for (const char* k : {"id", "input", "graph6", "realization", "realization_seed", "parameters", "status", "error", "time_ms"})
    line[k] = nullptr;
  for (const char* text : texts) {
    const scenes::Scene scene = scenes::loadSceneFromString(text, "fields");
    const Json r = jobResult(job, scene, job == Job::Track, {});
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
  RunResult result;

  // What the output holds already.
  std::vector<std::pair<Json, std::string>> done;
  const bool to_file = !out.empty() && out != "-";
  if (to_file) {
    std::error_code ec;
    if (std::filesystem::exists(out, ec) && std::filesystem::file_size(out, ec) > 0) {
      ReadLines old = readLines(out, true);
      if (old.summary) {
        if (withoutSlice((*old.summary)["sweep"]) != withoutSlice(params) ||
            (*old.summary)["sweep"].value("slice", "") != params.value("slice", ""))
          throw SceneError(out, static_cast<int>(old.items.size()) + 1, 1,
                           "holds the summary of another sweep (" + (*old.summary)["sweep"].dump() +
                               "): choose another output or remove it");
        for (const auto& [j, text] : old.items) result.tally.add(j);
        result.resumed = static_cast<long long>(old.items.size());
        result.complete = true;
        return result;
      }
      if (old.partial_tail) std::filesystem::resize_file(out, old.complete_bytes, ec);
      if (ec) throw present::OutputError("cannot cut the partial last line of " + out + ": " + ec.message());
      done = std::move(old.items);
    }
  }
  LineWriter writer(out);
  for (const auto& [j, text] : done) result.tally.add(j);
  result.resumed = static_cast<long long>(done.size());

  // The window of items in flight: claimed by the workers in order, written in order.
  struct Slot {
    Item item;
    Json line;
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

  auto worker = [&] {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      work.wait(lock, [&] { return quit || (!stopping && claimed < window.size()); });
      if (quit) return;
      Slot& s = window[claimed++];
      lock.unlock();
      bool stopped = false;
      Json line = computeItem(family, s.item, o, where ? &*where : nullptr, stop_now, stopped);
      std::string text = lineText(line);
      lock.lock();
      s.line = std::move(line);
      s.text = std::move(text);
      s.stopped = stopped;
      s.done = true;
      finished.notify_all();
    }
  };

  size_t next_done = 0;  // the next line of `done` the family's items must match
  bool exhausted = false;
  // The next item of this slice that the output does not hold.
  auto nextItem = [&](Item& item) {
    while (family.next(item)) {
      if (item.id % o.slice.n != o.slice.k) continue;
      if (next_done < done.size()) {
        const Json& d = done[next_done].first;
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
      window.push_back(Slot{std::move(item), Json(), std::string(), false, false});
      work.notify_one();
    }
  };

  std::vector<std::thread> pool;
  auto shutdown = [&] {
    {
      std::lock_guard<std::mutex> lock(m);
      quit = true;
    }
    work.notify_all();
    for (auto& t : pool) t.join();
    pool.clear();
  };
  try {
    refill();
    for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
    for (;;) {
      std::unique_lock<std::mutex> lock(m);
      if (window.empty()) break;
      finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return window.front().done; });
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
          result.tally.add(s.line);
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
        result.tally.add(s.line);
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
    if (next_done < done.size())
      throw SceneError(out, static_cast<int>(next_done) + 1, 1,
                       "holds items this sweep does not have: it is the output of another sweep");
    writer.add(lineText(summaryJson(params, result.tally, std::chrono::duration<double>(Clock::now() - t0).count())));
    result.complete = true;
  }
  writer.flush();
  return result;
}

Tally merge(const std::vector<std::string>& shards, const std::string& out) {
  if (shards.empty()) throw SceneError("merge", 1, 1, "no shard to merge");
  std::optional<Json> params;
  int n = 0;
  std::vector<int> seen;
  std::vector<std::pair<Json, std::string>> items;
  double wall = 0;
  for (const std::string& shard : shards) {
    ReadLines r = readLines(shard, false);
    const int line = static_cast<int>(r.items.size()) + 1;
    if (!r.summary) throw SceneError(shard, line, 1, "has no summary: the shard is incomplete (rerun its slice)");
    const Json& sweep = (*r.summary)["sweep"];
    const std::string slice = sweep.value("slice", "0/1");
    int k = -1, count = 0;
    if (std::sscanf(slice.c_str(), "%d/%d", &k, &count) != 2 || count < 1 || k < 0 || k >= count)
      throw SceneError(shard, line, 1, "the summary's slice '" + slice + "' is not k/N");
    if (!params) {
      params = withoutSlice(sweep);
      n = count;
      seen.assign(static_cast<size_t>(n), 0);
    } else if (withoutSlice(sweep) != *params || count != n) {
      throw SceneError(shard, line, 1, "is a shard of another sweep than " + shards[0]);
    }
    if (seen[static_cast<size_t>(k)]++) throw SceneError(shard, line, 1, "slice " + slice + " is given twice");
    wall = std::max(wall, (*r.summary).value("wall_time_s", 0.0));
    for (auto& it : r.items) {
      if (it.first["id"].get<long long>() % n != k)
        throw SceneError(shard, 1, 1, "item " + it.first["id"].dump() + " is not in slice " + slice);
      items.push_back(std::move(it));
    }
  }
  for (int k = 0; k < n; ++k)
    if (!seen[static_cast<size_t>(k)])
      throw SceneError(shards[0], 1, 1, "slice " + std::to_string(k) + "/" + std::to_string(n) + " is missing");
  std::sort(items.begin(), items.end(),
            [](const auto& a, const auto& b) { return a.first["id"].template get<long long>() < b.first["id"].template get<long long>(); });
  Tally t;
  std::string text;
  for (const auto& [j, line] : items) {
    t.add(j);
    text += line;
  }
  text += lineText(summaryJson(*params, t, wall));
  present::writeFileAtomically(out, text);
  return t;
}

}  // namespace flexure::sweep
