// SPDX-License-Identifier: GPL-2.0-or-later
// The console's gate over a real socket: each way a page the user did not open (or a
// careless client) could reach the card is refused, and the Api behind it is never called.
#include "console/server.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include "console/router.hpp"
#include "raw_client.hpp"

namespace i20::console {
namespace {

namespace fs = std::filesystem;
using testing::ask;
using testing::get_request;
using testing::post_request;

// Counts the requests that got through the gate.
class CountingApi : public Api {
 public:
  Response handle(const Request& request) override {
    ++calls;
    return make_response(http::status::ok, testing::cat("{\"echo\":\"", request.body(), "\"}"),
                         "application/json", request);
  }
  std::string live_sample() override { return "{\"sample\":42}"; }
  std::atomic<int> calls{0};
};

class ConsoleServer : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / testing::cat("i20-console-test-", std::to_string(::getpid()));
    fs::create_directories(root_ / "site");
    std::ofstream(root_ / "site" / "index.html") << "<title>console</title>";
    std::ofstream(root_ / "secret.html") << "outside the folder";
    // Short waits: the tests run through them (the live interval) or wait for a close.
    ServerOptions options{.timing = {.live_interval = std::chrono::milliseconds(20),
                                     .stop_poll = std::chrono::milliseconds(10),
                                     .drain = std::chrono::seconds(1),
                                     .idle = std::chrono::seconds(30)}};
    options.static_dir = root_ / "site";
    options.limits.body_bytes = 1024;
    options.limits.header_count = 20;
    server_ = std::make_unique<Server>(options, api_);
    port_ = server_->port();
    thread_ = std::thread([this] { server_->run(); });
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
    fs::remove_all(root_);
  }
  std::string cookie() const { return testing::cat("Cookie: i20_console=", server_->token(), "\r\n"); }
  std::string origin() const {
    return testing::cat("Origin: http://127.0.0.1:", std::to_string(port_), "\r\n");
  }
  std::string upgrade(const std::string& origin_line) const {
    return testing::cat("GET ", kLivePath, " HTTP/1.1\r\nHost: 127.0.0.1:", std::to_string(port_), "\r\n",
                        cookie(), origin_line,
                        "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n");
  }

  fs::path root_;
  CountingApi api_;
  std::unique_ptr<Server> server_;
  unsigned short port_ = 0;
  std::thread thread_;
};

TEST_F(ConsoleServer, ListensOnLoopbackAndPrintsATokenUrl) {
  EXPECT_EQ(server_->url(),
            testing::cat("http://127.0.0.1:", std::to_string(port_), "/?token=", server_->token()));
  EXPECT_EQ(server_->token().size(), 32u);
}

TEST_F(ConsoleServer, TheTokenIsTradedForAStrictHttpOnlyCookie) {
  const auto r = ask(port_, get_request(port_, testing::cat("/?token=", server_->token())));
  ASSERT_EQ(r.status, 303);
  EXPECT_EQ(r.header("Location"), "/");  // the token leaves the address bar
  const auto set = r.header("Set-Cookie");
  EXPECT_NE(set.find(testing::cat("i20_console=", server_->token())), std::string::npos);
  EXPECT_NE(set.find("HttpOnly"), std::string::npos);
  EXPECT_NE(set.find("SameSite=Strict"), std::string::npos);
  const auto page = ask(port_, get_request(port_, "/", cookie()));
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.body, "<title>console</title>");
}

TEST_F(ConsoleServer, RefusesARequestWithoutToken) {
  EXPECT_EQ(ask(port_, get_request(port_, "/")).status, 401);
  EXPECT_EQ(ask(port_, get_request(port_, "/api/overview")).status, 401);
  EXPECT_EQ(api_.calls, 0);
}

TEST_F(ConsoleServer, RefusesAWrongToken) {
  EXPECT_EQ(ask(port_, get_request(port_, "/?token=0123456789abcdef0123456789abcdef")).status, 403);
  EXPECT_EQ(ask(port_, get_request(port_, "/", "Cookie: i20_console=guess\r\n")).status, 401);
}

TEST_F(ConsoleServer, RefusesAnotherHostName) {  // DNS rebinding: the page's own name arrives as Host
  std::string request = testing::cat("GET / HTTP/1.1\r\nHost: evil.example:", std::to_string(port_),
                                     "\r\nConnection: close\r\n", cookie(), "\r\n");
  EXPECT_EQ(ask(port_, request).status, 421);
  request = testing::cat("GET / HTTP/1.1\r\nConnection: close\r\n", cookie(), "\r\n");  // none at all
  EXPECT_EQ(ask(port_, request).status, 421);
}

TEST_F(ConsoleServer, RefusesACrossOriginPost) {
  EXPECT_EQ(
      ask(port_, post_request(port_, "/api/apply", "NVKQP=50", cookie() + "Origin: http://evil.example\r\n"))
          .status,
      403);
  EXPECT_EQ(ask(port_, post_request(port_, "/api/apply", "NVKQP=50", cookie())).status, 403);  // no Origin
  EXPECT_EQ(api_.calls, 0);
  const auto ok = ask(port_, post_request(port_, "/api/apply", "NVKQP=50", cookie() + origin()));
  EXPECT_EQ(ok.status, 200);
  EXPECT_EQ(ok.body, "{\"echo\":\"NVKQP=50\"}");
  EXPECT_EQ(api_.calls, 1);
}

TEST_F(ConsoleServer, RefusesACrossSiteWebSocket) {
  EXPECT_EQ(ask(port_, upgrade("Origin: http://evil.example\r\n")).status, 403);
  EXPECT_EQ(ask(port_, upgrade("")).status, 403);
  // Its own page's upgrade is accepted and receives the live samples.
  const auto r = ask(port_, upgrade(origin()), "{\"sample\":42}");
  EXPECT_EQ(r.status, 101);
  EXPECT_NE(r.body.find("{\"sample\":42}"), std::string::npos);
}

TEST_F(ConsoleServer, RefusesAnOversizedBody) {
  const auto r = ask(port_, post_request(port_, "/api/apply", std::string(4096, 'x'), cookie() + origin()));
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(api_.calls, 0);
}

TEST_F(ConsoleServer, RefusesTooManyOrTooLargeHeaders) {
  std::string many;
  for (int i = 0; i < 30; ++i) many += testing::cat("X-Filler-", std::to_string(i), ": 1\r\n");
  EXPECT_EQ(ask(port_, get_request(port_, "/", cookie() + many)).status, 431);
  EXPECT_EQ(
      ask(port_, get_request(port_, "/", testing::cat(cookie(), "X-Big: ", std::string(20000, 'a'), "\r\n")))
          .status,
      431);
}

TEST_F(ConsoleServer, RefusesPathTraversal) {
  for (const std::string target : {"/../secret.html", "/%2e%2e/secret.html", "/%2E%2E%2Fsecret.html",
                                   "/..%2fsecret.html", "/site/..\\secret.html", "/.hidden.html", "/%zz"}) {
    const auto r = ask(port_, get_request(port_, target, cookie()));
    EXPECT_EQ(r.status, 400) << target;
    EXPECT_EQ(r.body.find("outside the folder"), std::string::npos) << target;
  }
  EXPECT_EQ(ask(port_, get_request(port_, "/missing.html", cookie())).status, 404);
  EXPECT_EQ(ask(port_, get_request(port_, "/index.txt", cookie())).status, 400);  // not a page type
}

TEST_F(ConsoleServer, RefusesOtherMethods) {
  std::string request =
      testing::cat("PUT / HTTP/1.1\r\nHost: 127.0.0.1:", std::to_string(port_),
                   "\r\nConnection: close\r\nContent-Length: 0\r\n", cookie(), origin(), "\r\n");
  EXPECT_EQ(ask(port_, request).status, 405);
}

TEST_F(ConsoleServer, RefusesAMalformedRequest) {
  EXPECT_EQ(ask(port_, "NOT HTTP AT ALL\r\n\r\n").status, 400);
}

}  // namespace
}  // namespace i20::console
