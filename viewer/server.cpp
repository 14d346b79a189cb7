#include "viewer/server.h"

#include <httplib.h>

#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <condition_variable>
#include <deque>

#include "present/output_file.h"
#include "scenes/json_text.h"
#include "present/text.h"

namespace flexure::viewer {

namespace {

using Clock = std::chrono::steady_clock;

// A token bucket: `rate` requests per second, bursts up to one second's worth.
class RateLimit {
 public:
  explicit RateLimit(double rate) : rate_(rate), tokens_(rate), last_(Clock::now()) {}
  bool take() {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = Clock::now();
    tokens_ = std::min(rate_, tokens_ + rate_ * std::chrono::duration<double>(now - last_).count());
    last_ = now;
    if (tokens_ < 1) return false;
    tokens_ -= 1;
    return true;
  }

 private:
  std::mutex mutex_;
  double rate_, tokens_;
  Clock::time_point last_;
};

// A request parameter that is wrong: 400 with this message.
struct BadRequest : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

double number(const httplib::Request& req, const char* key, double fallback, double lo, double hi) {
  if (!req.has_param(key)) return fallback;
  const std::string s = req.get_param_value(key);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (!s.empty() && *end == '\0' && std::isfinite(v) && v >= lo && v <= hi) return v;
  char range[96];
  std::snprintf(range, sizeof range, " must be a number in [%g, %g], not '", lo, hi);
  throw BadRequest(key + std::string(range) + s.substr(0, 40) + "'");
}

int integer(const httplib::Request& req, const char* key, int fallback, int lo, int hi) {
  const double v = number(req, key, fallback, lo, hi);
  if (v != std::floor(v)) throw BadRequest(std::string(key) + " must be an integer");
  return static_cast<int>(v);
}

std::optional<bool> flag(const httplib::Request& req, const char* key) {
  if (!req.has_param(key)) return std::nullopt;
  const std::string s = req.get_param_value(key);
  if (s == "1" || s == "true") return true;
  if (s == "0" || s == "false") return false;
  throw BadRequest(std::string(key) + " must be 0 or 1");
}

void json(httplib::Response& res, const nlohmann::ordered_json& j, int status = 200) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  // With a charset: httplib compresses exactly "application/json" (and text/*) for clients
  // that accept it, with Brotli at its slowest setting (about 1 ms per KB: most of a drag's
  // time for a large framework). On the loopback interface compression only costs.
  res.set_content(present::jsonText(j), "application/json; charset=utf-8");
}

void fail(httplib::Response& res, int status, const std::string& message) {
  json(res, {{"error", message}}, status);
}

void png(httplib::Response& res, const std::vector<std::uint8_t>& bytes) {
  if (bytes.empty()) return fail(res, 503, "nothing to show yet: the scene has not loaded");
  res.set_header("Cache-Control", "no-store");
  res.set_content(reinterpret_cast<const char*>(bytes.data()), bytes.size(), "image/png");
}

// The body of a POST: a JSON object (the content type too, so that a plain cross-site form
// cannot post here without a CORS preflight, which is never answered).
nlohmann::json body(const httplib::Request& req) {
  if (req.get_header_value("Content-Type").rfind("application/json", 0) != 0)
    throw BadRequest("the body must be application/json");
  try {
    scenes::checkJsonShape(req.body, "the body");
  } catch (const std::exception& e) {  // too deep (SceneError), too large (ResourceError)
    throw BadRequest(e.what());
  }
  nlohmann::json j = nlohmann::json::parse(req.body, nullptr, false);
  if (!j.is_object()) throw BadRequest("the body must be a JSON object");
  return j;
}

MotionControls controlsFrom(const nlohmann::json& j) {
  MotionControls c;
  auto field = [&](const char* key) -> std::optional<double> {
    if (!j.contains(key) || j[key].is_null()) return std::nullopt;
    if (!j[key].is_number()) throw BadRequest(std::string(key) + " must be a number");
    return j[key].get<double>();
  };
  if (j.contains("flex") && !j["flex"].is_null()) {
    const auto& f = j["flex"];
    if (f.is_string() && f.get<std::string>() == "auto") {
      c.flex = std::vector<double>{};
    } else if (f.is_array() && !f.empty() && f.size() <= 1000) {
      std::vector<double> v;
      for (const auto& x : f) {
        if (!x.is_number()) throw BadRequest("flex coefficients must be numbers");
        v.push_back(x.get<double>());
      }
      bool nonzero = false;
      for (double x : v) nonzero = nonzero || x != 0;
      if (!nonzero) throw BadRequest("flex coefficients must not all be zero");
      c.flex = v;
    } else {
      throw BadRequest("flex must be \"auto\" or a list of coefficients");
    }
  }
  c.step_size = field("step_size");
  if (const auto s = field("steps")) {
    if (*s != std::floor(*s) || *s < 0 || *s > 1e9) throw BadRequest("steps must be a nonnegative integer");
    c.steps = static_cast<int>(*s);
  }
  if (const auto s = field("seed")) {
    if (*s != std::floor(*s) || *s < 0 || *s > 9007199254740992.0) throw BadRequest("seed must be a nonnegative integer");
    c.seed = static_cast<std::uint64_t>(*s);
  }
  if (j.contains("certify") && !j["certify"].is_null()) {
    if (!j["certify"].is_boolean()) throw BadRequest("certify must be true or false");
    c.certify = j["certify"].get<bool>();
  }
  return c;
}

// httplib's default pool has a few workers that a handful of idle keep-alive connections, or
// clients that send a byte a second, keep busy. Here every connection gets a thread of its own,
// up to a limit; each waits at most request_timeout for a request and for each read.
class ConnectionThreads : public httplib::TaskQueue {
 public:
  explicit ConnectionThreads(int max) : max_(max) {}
  void enqueue(std::function<void()> fn) override {
    std::lock_guard<std::mutex> lock(m_);
    if (active_ >= max_) {
      pending_.push_back(std::move(fn));
      return;
    }
    ++active_;
    std::thread([this, fn = std::move(fn)]() mutable { work(std::move(fn)); }).detach();
  }
  // Every connection has ended (they end within the timeouts once the server stops).
  void shutdown() override {
    std::unique_lock<std::mutex> lock(m_);
    idle_.wait(lock, [this] { return active_ == 0; });
  }

 private:
  void work(std::function<void()> fn) {
    for (;;) {
      fn();
      std::lock_guard<std::mutex> lock(m_);
      if (pending_.empty()) {
        if (--active_ == 0) idle_.notify_all();
        return;
      }
      fn = std::move(pending_.front());
      pending_.pop_front();
    }
  }
  const int max_;
  std::mutex m_;
  std::condition_variable idle_;
  int active_ = 0;
  std::deque<std::function<void()>> pending_;
};

}  // namespace

struct Server::Impl {
  Session& session;
  ServerOptions options;
  httplib::Server http;
  RateLimit images, posts, drags;
  int port = -1;
  std::atomic<int> listening{-1};  // the listening socket, seen by the socket-options hook

  Impl(Session& s, ServerOptions o)
      : session(s), options(o), images(o.images_per_second), posts(o.posts_per_second), drags(o.drags_per_second) {}

  // Loopback names only, at our port: a page elsewhere that points a DNS name at 127.0.0.1
  // gets nothing.
  bool hostAllowed(const std::string& host) const {
    const std::string p = ":" + std::to_string(port);
    return host == "127.0.0.1" + p || host == "localhost" + p || host == "[::1]" + p;
  }
  bool originAllowed(const std::string& origin) const {
    return origin.empty() || origin == "http://127.0.0.1:" + std::to_string(port) ||
           origin == "http://localhost:" + std::to_string(port);
  }

  // "STEM_what.ext" for a download, from the scene's file name (safe characters only).
  std::string downloadName(const std::string& what, const std::string& ext) const {
    std::string safe;
    for (char c : present::stemOf(session.scenePath()))
      safe += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ? c : '_';
    return safe + "_" + what + "." + ext;
  }
  void download(httplib::Response& res, const std::string& content, const std::string& what, const std::string& ext,
                const char* type) const {
    if (content.empty()) return fail(res, 503, "nothing to export yet: the scene has not loaded");
    res.set_header("Cache-Control", "no-store");
    res.set_header("Content-Disposition", "attachment; filename=\"" + downloadName(what, ext) + "\"");
    res.set_content(content, type);
  }

  // Runs a handler; turns the errors it throws into the right status.
  template <class F>
  void guarded(httplib::Response& res, F&& f) {
    try {
      f();
    } catch (const BadRequest& e) {
      fail(res, 400, e.what());
    } catch (const std::invalid_argument& e) {
      fail(res, 422, e.what());
    } catch (const std::exception& e) {  // OutputError (a save that failed) among them
      fail(res, 500, e.what());
    }
  }

  void routes() {
    http.set_payload_max_length(options.max_body);
    const int max_connections = options.max_connections;
    http.new_task_queue = [max_connections] { return new ConnectionThreads(max_connections); };
    http.set_read_timeout(options.request_timeout, 0);
    http.set_keep_alive_timeout(options.request_timeout);
    http.set_write_timeout(5, 0);
    http.set_keep_alive_max_count(1000);
    http.set_tcp_nodelay(true);
    // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, which lets a second viewer
    // bind the same port and share its connections.
    http.set_socket_options([this](socket_t sock) {
      listening = sock;
      int yes = 1;
      ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });  // headers and body go out at once (no 40 ms delayed-ACK stall)
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      if (!hostAllowed(req.get_header_value("Host"))) {
        fail(res, 403, "this viewer answers only to http://127.0.0.1:" + std::to_string(port));
        return httplib::Server::HandlerResponse::Handled;
      }
      // A chunked body has no length to check before it is read (httplib reads it whole): the
      // viewer's own page always sends Content-Length.
      if (req.has_header("Transfer-Encoding")) {
        res.set_header("Connection", "close");
        fail(res, 411, "send the body with a Content-Length (chunked bodies are refused)");
        return httplib::Server::HandlerResponse::Handled;
      }
      if (req.method != "GET" && req.method != "HEAD" && !originAllowed(req.get_header_value("Origin"))) {
        fail(res, 403, "cross-origin requests are refused");
        return httplib::Server::HandlerResponse::Handled;
      }
      res.set_header("X-Content-Type-Options", "nosniff");
      res.set_header("X-Frame-Options", "DENY");
      res.set_header("Referrer-Policy", "no-referrer");
      return httplib::Server::HandlerResponse::Unhandled;
    });

    http.Get("/", [](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      res.set_header("Content-Security-Policy",
                     "default-src 'none'; img-src 'self' blob:; style-src 'unsafe-inline'; "
                     "script-src 'unsafe-inline'; connect-src 'self'; form-action 'none'; frame-ancestors 'none'");
      res.set_content(viewerPage(), "text/html; charset=utf-8");
    });

    http.Get("/api/state", [this](const httplib::Request& req, httplib::Response& res) {
      guarded(res, [&] {
        if (req.has_param("since")) {
          const std::string since = req.get_param_value("since");
          if (since == std::to_string(session.revision())) return json(res, {{"revision", session.revision()},
                                                                             {"unchanged", true}});
        }
        json(res, session.state());
      });
    });

    // The frame as the page shows it: PNG, or for export SVG, PDF and TikZ (same parameters).
    const auto frameRequest = [this](const httplib::Request& req) {
      FrameRequest q;
      q.sample = integer(req, "sample", 0, 0, 100000000);
      q.width = integer(req, "w", 800, 16, options.max_image_side);
      q.height = integer(req, "h", 800, 16, options.max_image_side);
      if (req.has_param("az")) q.options.azimuth = number(req, "az", 0, -1e6, 1e6);
      if (req.has_param("el")) q.options.elevation = number(req, "el", 0, -1.57, 1.57);
      q.options.zoom = number(req, "zoom", 1, 0.05, 50);
      q.options.labels = flag(req, "labels");
      q.options.trace = flag(req, "trace");
      q.options.flex = flag(req, "flex").value_or(false);
      q.options.pan_x = number(req, "pan_x", 0, -1e5, 1e5);
      q.options.pan_y = number(req, "pan_y", 0, -1e5, 1e5);
      q.dragged = flag(req, "dragged").value_or(false);
      q.after = static_cast<std::uint64_t>(number(req, "after", 0, 0, 9007199254740992.0));
      return q;
    };
    http.Get("/frame.png", [this, frameRequest](const httplib::Request& req, httplib::Response& res) {
      if (!images.take()) return fail(res, 429, "too many image requests");
      guarded(res, [&] {
        const FrameRequest q = frameRequest(req);
        if (flag(req, "download").value_or(false))
          res.set_header("Content-Disposition", "attachment; filename=\"" + downloadName("frame", "png") + "\"");
        png(res, session.framePng(q));
      });
    });
    for (const char* ext : {"svg", "pdf", "tex"}) {
      http.Get(std::string("/frame.") + ext, [this, frameRequest, ext](const httplib::Request& req, httplib::Response& res) {
        if (!images.take()) return fail(res, 429, "too many image requests");
        guarded(res, [&] {
          render::VectorFormat format;
          render::vectorFormatOf(ext, format);
          const std::string type = std::string(ext) == "svg"   ? "image/svg+xml; charset=utf-8"
                                   : std::string(ext) == "pdf" ? "application/pdf"
                                                               : "application/x-tex; charset=utf-8";
          const std::string text = session.frameVector(frameRequest(req), format);
          if (text.empty()) return fail(res, 503, "nothing loaded yet");
          download(res, text, "frame", ext, type.c_str());
        });
      });
    }

    http.Get("/path.json", [this](const httplib::Request&, httplib::Response& res) {
      guarded(res, [&] { download(res, session.pathText(false), "path", "json", "application/json; charset=utf-8"); });
    });
    http.Get("/path.csv", [this](const httplib::Request&, httplib::Response& res) {
      guarded(res, [&] { download(res, session.pathText(true), "path", "csv", "text/csv; charset=utf-8"); });
    });

    http.Post("/api/drag", [this](const httplib::Request& req, httplib::Response& res) {
      if (!drags.take()) return fail(res, 429, "too many drag requests");
      guarded(res, [&] {
        const nlohmann::json j = body(req);
        if (!j.contains("vertex") || !j["vertex"].is_number_integer())
          throw BadRequest("vertex must be an integer (numbered as in the scene file)");
        const auto& to = j.contains("to") ? j["to"] : nlohmann::json();
        if (!to.is_array() || to.size() != 2 || !to[0].is_number() || !to[1].is_number())
          throw BadRequest("to must be [px, py]: pixels of the current frame from its top left");
        const double px = to[0].get<double>(), py = to[1].get<double>();
        if (!std::isfinite(px) || !std::isfinite(py) || std::abs(px) > 1e6 || std::abs(py) > 1e6)
          throw BadRequest("to must be finite pixels within 1e6 of the frame");
        const long long v = j["vertex"].get<long long>();
        if (v < -1000000000LL || v > 1000000000LL) throw BadRequest("vertex out of range");
        std::uint64_t seq = 0;
        if (j.contains("seq")) {
          if (!j["seq"].is_number_unsigned()) throw BadRequest("seq must be a nonnegative integer");
          seq = j["seq"].get<std::uint64_t>();
        }
        json(res, session.drag(static_cast<int>(v), px, py, seq));
      });
    });

    http.Post("/api/start", [this](const httplib::Request& req, httplib::Response& res) {
      if (!posts.take()) return fail(res, 429, "too many requests");
      guarded(res, [&] {
        (void)body(req);
        session.startFromDragged();
        json(res, session.state());
      });
    });

    http.Post("/api/branch", [this](const httplib::Request& req, httplib::Response& res) {
      if (!posts.take()) return fail(res, 429, "too many requests");
      guarded(res, [&] {
        const nlohmann::json j = body(req);
        for (const char* key : {"sample", "direction"})
          if (!j.contains(key) || !j[key].is_number_integer() || j[key].get<long long>() < 0 ||
              j[key].get<long long>() > 100000000LL)
            throw BadRequest(std::string(key) + " must be a nonnegative integer");
        session.followBranch(j["sample"].get<int>(), j["direction"].get<int>());
        json(res, session.state());
      });
    });

    http.Get("/projection.png", [this](const httplib::Request& req, httplib::Response& res) {
      if (!images.take()) return fail(res, 429, "too many image requests");
      guarded(res, [&] {
        const int sample = integer(req, "sample", 0, 0, 100000000);
        const int w = integer(req, "w", 500, 16, options.max_image_side);
        const int h = integer(req, "h", 500, 16, options.max_image_side);
        png(res, session.projectionPng(sample, w, h));
      });
    });

    http.Get("/scene.toml", [this](const httplib::Request&, httplib::Response& res) {
      guarded(res, [&] { download(res, session.sceneText(), "view", "toml", "application/toml; charset=utf-8"); });
    });

    http.Post("/api/motion", [this](const httplib::Request& req, httplib::Response& res) {
      if (!posts.take()) return fail(res, 429, "too many requests");
      guarded(res, [&] {
        session.setControls(controlsFrom(body(req)));
        json(res, session.state());
      });
    });

    http.Post("/api/reset", [this](const httplib::Request& req, httplib::Response& res) {
      if (!posts.take()) return fail(res, 429, "too many requests");
      guarded(res, [&] {
        (void)body(req);
        session.resetControls();
        json(res, session.state());
      });
    });

    http.Post("/api/save", [this](const httplib::Request& req, httplib::Response& res) {
      if (!posts.take()) return fail(res, 429, "too many requests");
      guarded(res, [&] {
        const nlohmann::json j = body(req);
        if (!j.contains("name") || !j["name"].is_string()) throw BadRequest("name must be a file name");
        const bool overwrite = j.contains("overwrite") && j["overwrite"].is_boolean() && j["overwrite"].get<bool>();
        const std::string file = session.saveAs(j["name"].get<std::string>(), overwrite);
        json(res, {{"saved", file}});
      });
    });
  }
};

Server::Server(Session& session, ServerOptions options) : impl_(std::make_unique<Impl>(session, options)) {
  impl_->routes();
}

Server::~Server() { stop(); }

int Server::bind(int port) {
  Impl& m = *impl_;
  if (port == 0) m.port = m.http.bind_to_any_port("127.0.0.1");
  else m.port = m.http.bind_to_port("127.0.0.1", port) ? port : -1;
  // httplib listens with a backlog of 5: a burst of connections (a page's requests, or 500
  // idle sockets) would have its SYNs dropped and retried a second later. Listening again
  // raises the backlog.
  if (m.port > 0 && m.listening >= 0) ::listen(m.listening, 1024);
  return m.port;
}

void Server::run(const volatile std::sig_atomic_t* stop_flag) {
  Impl& m = *impl_;
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    auto next_look = Clock::now();
    while (!done) {
      // Until listen returns: a stop before it started running would be lost.
      if (stop_flag && *stop_flag) m.http.stop();
      if (Clock::now() >= next_look) {
        m.session.checkFile();
        next_look = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(m.options.watch_interval));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  m.http.listen_after_bind();
  done = true;
  watcher.join();
}

void Server::stop() {
  if (impl_ && impl_->http.is_running()) impl_->http.stop();
}

}  // namespace flexure::viewer
