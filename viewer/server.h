// The viewer's HTTP side: one page (embedded in the binary), its JSON API and the images it
// shows, on the loopback interface only. It serves nothing else: no file is ever named by a
// request. Requests are bounded (body size, image size, rates) and checked for a loopback
// Host and Origin, so that no other web page can drive it (DNS rebinding, cross-site POSTs).
#pragma once

#include <atomic>
#include <csignal>
#include <functional>
#include <memory>
#include <string>

#include "viewer/session.h"

namespace flexure::viewer {

struct ServerOptions {
  int max_image_side = 2048;            // px, each of width and height
  double images_per_second = 120;       // frames and plots, all clients together
  double posts_per_second = 10;         // motion changes and saves
  double drags_per_second = 250;        // POST /api/drag (pointer moves)
  double watch_interval = 0.25;         // s between looks at the scene file
  std::size_t max_body = 64 * 1024;     // bytes of a POST body
  // Connections: each has its own thread (idle or slow clients cannot occupy a small pool),
  // at most this many at once; more wait for one to end.
  int max_connections = 1024;
  int request_timeout = 2;              // s to wait for a request, and for each read of one
};

// The page, as served at "/".
const char* viewerPage();

class Server {
 public:
  Server(Session& session, ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds 127.0.0.1:port (a free port for 0); returns the port, or -1 when it is taken.
  int bind(int port);
  // Serves and watches the scene file until stop() (from any thread) or until `stop_flag`
  // becomes true (a signal handler's flag; checked every 0.1 s).
  void run(const volatile std::sig_atomic_t* stop_flag = nullptr);
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flexure::viewer
