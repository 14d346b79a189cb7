#include "viewer/server.h"

#include <httplib.h>

#include <catch2/catch.hpp>
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
                           "{\"step_size\": \"big\"}", "{\"seed\": -1}", "not json"}) {
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
