#include "viewer/server.h"

#include <httplib.h>

#include <catch2/catch.hpp>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "render/image.h"

#include "tests/viewer/viewer_test_common.h"

using namespace flexure;
using flexure::test::ScratchScene;

namespace {

// A viewer on a free port, served from a thread for the test's lifetime.
struct Running {
  explicit Running(const std::string& example, viewer::ServerOptions o = {})
      : scene(example), session(scene.path, sessionOptions()), server(session, o) {
    port = server.bind(0);
    REQUIRE(port > 0);
    thread = std::thread([this] { server.run(); });
    client = std::make_unique<httplib::Client>("127.0.0.1", port);
    for (int i = 0; i < 200 && !client->Get("/api/state"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    REQUIRE(session.waitIdle(30));
  }
  ~Running() {
    server.stop();
    thread.join();
  }
  static viewer::SessionOptions sessionOptions() {
    viewer::SessionOptions o;
    o.overrides = {"motion.steps=30"};
    return o;
  }
  httplib::Result post(const std::string& path, const std::string& body,
                       const httplib::Headers& headers = {}) {
    return client->Post(path.c_str(), headers, body, "application/json");
  }
  ScratchScene scene;
  viewer::Session session;
  viewer::Server server;
  int port = 0;
  std::thread thread;
  std::unique_ptr<httplib::Client> client;
};

}  // namespace

TEST_CASE("Server: the page, the state and the images", "[viewer]") {
  Running r("double_watt");
  auto res = r.client->Get("/");
  REQUIRE(res);
  CHECK(res->status == 200);
  CHECK(res->get_header_value("Content-Type") == "text/html; charset=utf-8");
  CHECK(res->get_header_value("Content-Security-Policy").find("default-src 'none'") != std::string::npos);
  CHECK(res->body.find("flexure view") != std::string::npos);

  res = r.client->Get("/api/state");
  REQUIRE(res);
  const auto st = nlohmann::json::parse(res->body);
  CHECK(st["loaded"]["samples"] == 31);
  res = r.client->Get(("/api/state?since=" + std::to_string(st["revision"].get<std::uint64_t>())).c_str());
  CHECK(nlohmann::json::parse(res->body)["unchanged"] == true);

  res = r.client->Get("/frame.png?sample=10&w=200&h=150&az=1&el=0.3&zoom=2&labels=0&flex=1&trace=1");
  REQUIRE(res);
  CHECK(res->status == 200);
  CHECK(res->get_header_value("Content-Type") == "image/png");
  const render::Image im = render::decodePng({res->body.begin(), res->body.end()});
  CHECK(im.width == 200);
  CHECK(im.height == 150);
  res = r.client->Get("/projection.png?sample=3&w=120&h=100");
  REQUIRE(res);
  CHECK(res->status == 200);

  res = r.client->Get("/scene.toml");
  REQUIRE(res);
  CHECK(res->get_header_value("Content-Disposition") == "attachment; filename=\"double_watt_view.toml\"");
  CHECK(res->body.find("[system]") != std::string::npos);
}

TEST_CASE("Server: serves nothing but its own routes, and checks every parameter", "[viewer]") {
  Running r("double_watt");
  for (const char* path : {"/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/double_watt.toml", "/viewer/page.html",
                           "/frame.png/../../etc/passwd", "/api", "/index.html", "//etc/passwd"}) {
    INFO(path);
    auto res = r.client->Get(path);
    REQUIRE(res);
    CHECK((res->status == 404 || res->status == 400));
    CHECK(res->body.find("root:") == std::string::npos);
    CHECK(res->body.find("[system]") == std::string::npos);
  }
  for (const char* path : {"/frame.png?w=100000", "/frame.png?w=15", "/frame.png?sample=-1", "/frame.png?sample=abc",
                           "/frame.png?zoom=0", "/frame.png?el=2", "/frame.png?az=nan", "/frame.png?labels=yes",
                           "/projection.png?h=99999", "/frame.png?w=10.5"}) {
    INFO(path);
    auto res = r.client->Get(path);
    REQUIRE(res);
    CHECK(res->status == 400);
  }
}

TEST_CASE("Server: loopback names only, no cross-origin posts, JSON bodies, bounded sizes", "[viewer]") {
  viewer::ServerOptions o;
  o.posts_per_second = 1000;  // not what this case is about
  Running r("double_watt", o);
  httplib::Headers evil_host = {{"Host", "attacker.example:" + std::to_string(r.port)}};
  auto res = r.client->Get("/api/state", evil_host);
  REQUIRE(res);
  CHECK(res->status == 403);  // DNS rebinding: a foreign name pointed at 127.0.0.1
  res = r.client->Get("/", {{"Host", "127.0.0.1:1"}});
  REQUIRE(res);
  CHECK(res->status == 403);

  res = r.post("/api/motion", R"({"steps": 12})", {{"Origin", "http://attacker.example"}});
  REQUIRE(res);
  CHECK(res->status == 403);
  res = r.client->Post("/api/motion", R"({"steps": 12})", "text/plain");  // a plain form's type
  REQUIRE(res);
  CHECK(res->status == 400);
  res = r.post("/api/motion", std::string(70000, ' ') + "{}");
  REQUIRE(res);
  CHECK(res->status == 413);
  for (const char* body : {"[]", "{\"steps\": -3}", "{\"steps\": 1.5}", "{\"flex\": [0, 0]}", "{\"flex\": \"x\"}",
                           "{\"step_size\": \"big\"}", "{\"seed\": -1}", "{\"certify\": 1}", "not json"}) {
    INFO(body);
    res = r.post("/api/motion", body);
    REQUIRE(res);
    CHECK(res->status == 400);
  }
  res = r.post("/api/motion", R"({"flex": [1, 2, 3]})");
  REQUIRE(res);
  CHECK(res->status == 422);  // the scene has two flexes

  res = r.post("/api/motion", R"({"steps": 12, "flex": "auto"})");
  REQUIRE(res);
  CHECK(res->status == 200);
  REQUIRE(r.session.waitIdle(30));
  CHECK(r.session.state()["loaded"]["samples"] == 13);

  res = r.post("/api/save", R"({"name": "../../x.toml"})");
  REQUIRE(res);
  CHECK(res->status == 422);
  res = r.post("/api/save", R"({"name": "saved.toml"})");
  REQUIRE(res);
  CHECK(res->status == 200);
  CHECK(nlohmann::json::parse(res->body)["saved"] == r.scene.dir + "/saved.toml");
  res = r.post("/api/save", R"({"name": "saved.toml"})");
  REQUIRE(res);
  CHECK(res->status == 422);  // exists
}

TEST_CASE("Server: request rates are bounded", "[viewer]") {
  viewer::ServerOptions o;
  o.posts_per_second = 2;
  o.images_per_second = 3;
  Running r("triangle", o);
  int refused = 0;
  for (int i = 0; i < 6; ++i) {
    auto res = r.client->Get("/frame.png?w=32&h=32");
    REQUIRE(res);
    refused += res->status == 429;
  }
  CHECK(refused >= 2);
  refused = 0;
  for (int i = 0; i < 5; ++i) {
    auto res = r.post("/api/reset", "{}");
    REQUIRE(res);
    refused += res->status == 429;
  }
  CHECK(refused >= 2);
}

TEST_CASE("Server: stops when its stop flag is raised (Ctrl-C)", "[viewer]") {
  ScratchScene scene("triangle");
  viewer::Session session(scene.path);
  viewer::Server server(session, {});
  REQUIRE(server.bind(0) > 0);
  volatile std::sig_atomic_t flag = 1;  // raised before it even runs
  const auto t0 = std::chrono::steady_clock::now();
  server.run(&flag);
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
}

namespace {

// A raw TCP connection to the viewer (what a hostile or broken client does).
int connectTo(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  return s;
}

void sendAll(int s, const std::string& data) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::send(s, data.data() + done, data.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return;  // the server closed it: fine
    done += static_cast<size_t>(n);
  }
}

}  // namespace

TEST_CASE("Server: answers with 500 idle and 30 slow connections open, and refuses chunked bodies", "[viewer]") {
  Running r("double_watt");
  std::vector<int> idle, slow;
  for (int i = 0; i < 500; ++i) idle.push_back(connectTo(r.port));
  // Slow clients: a request line, then a header line now and then, never the end.
  for (int i = 0; i < 30; ++i) {
    slow.push_back(connectTo(r.port));
    sendAll(slow.back(), "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(r.port) + "\r\n");
  }
  std::atomic<bool> dripping{true};
  std::thread drip([&] {
    while (dripping) {
      for (int s : slow) sendAll(s, "X-Slow: 1\r\n");
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  });
  httplib::Client fresh("127.0.0.1", r.port);
  fresh.set_read_timeout(5, 0);
  fresh.set_connection_timeout(5, 0);
  const auto t0 = std::chrono::steady_clock::now();
  auto res = fresh.Get("/api/state");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  REQUIRE(res);
  CHECK(res->status == 200);
  CHECK(seconds < 3);  // httplib's pool alone: no answer within 8 s behind 200 idle connections
  // A chunked body: refused before it is read, whatever its size.
  const int c = connectTo(r.port);
  sendAll(c, "POST /api/motion HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(r.port) +
                 "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n");
  const std::string chunk = "100000\r\n" + std::string(0x100000, ' ') + "\r\n";
  for (int i = 0; i < 8; ++i) sendAll(c, chunk);
  char buf[64] = {};
  timeval tv{5, 0};
  ::setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  CHECK(::recv(c, buf, sizeof buf - 1, 0) > 0);
  CHECK(std::string(buf).rfind("HTTP/1.1 411", 0) == 0);
  ::close(c);
  dripping = false;
  drip.join();
  for (int s : idle) ::close(s);
  for (int s : slow) ::close(s);
}

TEST_CASE("Server: the drag API, with the state of the frame shown, checked drags and the exports", "[viewer]") {
  Running r("double_watt");
  const httplib::Headers origin{{"Origin", "http://127.0.0.1:" + std::to_string(r.port)}};
  // The current frame: the last one asked for.
  REQUIRE(r.client->Get("/frame.png?sample=12&w=400&h=400"));
  auto res = r.client->Get("/api/state");
  REQUIRE(res);
  auto st = nlohmann::json::parse(res->body);
  REQUIRE(st["vertices"].size() == 11);
  REQUIRE(st["screen"].size() == 11);
  CHECK(st["view"]["sample"] == 12);
  CHECK(st["view"]["dragged"] == false);
  CHECK(st["residual"].get<double>() <= 1e-10);
  CHECK(st["loaded"]["index_base"] == 1);
  CHECK(st["loaded"]["pinned"] == nlohmann::json::array({1, 6, 11}));
  // Screen positions are inside the frame.
  for (const auto& p : st["screen"]) {
    CHECK(p[0].get<double>() > 0);
    CHECK(p[0].get<double>() < 400);
    CHECK(p[1].get<double>() > 0);
    CHECK(p[1].get<double>() < 400);
  }

  // Bad drags: 400 for a malformed body, 422 for a vertex that cannot be dragged.
  for (const char* body : {R"({"to": [1, 2]})", R"({"vertex": 4})", R"({"vertex": 4, "to": [1]})",
                           R"({"vertex": "4", "to": [1, 2]})", R"({"vertex": 4, "to": [1, "x"]})",
                           R"({"vertex": 4, "to": [1e300, 2]})", R"({"vertex": 4, "to": [1, 2], "seq": -1})"}) {
    res = r.post("/api/drag", body);
    REQUIRE(res);
    INFO(body);
    CHECK(res->status == 400);
  }
  res = r.post("/api/drag", R"({"vertex": 1, "to": [10, 10]})");
  CHECK(res->status == 422);
  CHECK(res->body.find("vertex 1 is pinned") != std::string::npos);
  res = r.post("/api/drag", R"({"vertex": 12, "to": [10, 10]})");
  CHECK(res->status == 422);
  CHECK(res->body.find("does not exist (1..11)") != std::string::npos);
  res = r.post("/api/drag", R"({"vertex": 4, "to": [10, 10]})", {{"Origin", "http://example.com"}});
  CHECK(res->status == 403);
  res = r.post("/api/start", "{}");
  CHECK(res->status == 422);  // nothing dragged yet

  // A drag of vertex 4 by 6 pixels up: the answer is the new state.
  const double x = st["screen"][3][0], y = st["screen"][3][1];
  res = r.post("/api/drag", nlohmann::json({{"vertex", 4}, {"to", {x, y - 6}}}).dump(), origin);
  REQUIRE(res);
  REQUIRE(res->status == 200);
  st = nlohmann::json::parse(res->body);
  CHECK(st["view"]["dragged"] == true);
  CHECK(st["drag"]["vertex"] == 4);
  CHECK(st["residual"].get<double>() <= 1e-10);
  CHECK(std::hypot(st["screen"][3][0].get<double>() - x, st["screen"][3][1].get<double>() - (y - 6)) < 6);
  for (int i : {0, 5, 10}) CHECK(st["vertices"][i] == nlohmann::json::parse(r.client->Get("/api/state")->body)["vertices"][i]);
  res = r.client->Get("/frame.png?sample=12&w=400&h=400&dragged=1&after=1");
  CHECK(res->status == 200);
  // The dragged frame exports as vectors too: the same figure, vertex 4 where the drag left it.
  res = r.client->Get("/frame.svg?sample=12&w=400&h=400&dragged=1");
  REQUIRE(res);
  CHECK(res->status == 200);
  CHECK(res->get_header_value("Content-Type").rfind("image/svg+xml", 0) == 0);
  CHECK(res->get_header_value("Content-Disposition").find(".svg") != std::string::npos);
  int joints = 0;
  for (size_t at = res->body.find("class=\"joint\""); at != std::string::npos; at = res->body.find("class=\"joint\"", at + 1))
    ++joints;
  CHECK(joints == 11);
  CHECK(res->body.find("class=\"holding\"") == std::string::npos);  // moved freely: nothing holds it
  res = r.client->Get("/frame.pdf?sample=12&w=400&h=400");
  REQUIRE(res);
  CHECK(res->body.rfind("%PDF-", 0) == 0);
  res = r.client->Get("/frame.tex?sample=12&w=400&h=400");
  REQUIRE(res);
  CHECK(res->body.find("\\begin{tikzpicture}") != std::string::npos);
  res = r.client->Get("/frame.svg?sample=12&w=400&h=400&zoom=-3");
  CHECK(res->status == 400);

  // Exports.
  res = r.client->Get("/path.json");
  REQUIRE(res);
  CHECK(res->get_header_value("Content-Disposition").find("attachment") != std::string::npos);
  CHECK(nlohmann::json::parse(res->body)["samples"].size() == 31);
  res = r.client->Get("/path.csv");
  CHECK(res->body.rfind("sample,", 0) == 0);
  // Branches: a sample that is not singular, and a direction that does not exist.
  res = r.post("/api/branch", R"({"sample": 5, "direction": 0})");
  CHECK(res->status == 422);
  res = r.post("/api/branch", R"({"sample": -1, "direction": 0})");
  CHECK(res->status == 400);
  res = r.post("/api/branch", R"({"sample": 0, "direction": 99})");
  CHECK(res->status == 422);
}
