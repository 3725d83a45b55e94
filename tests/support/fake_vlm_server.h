// A chat-completions server on 127.0.0.1 (cpp-httplib) whose replies a test
// scripts: the vlm refiner's, estimator's and identifier's tests talk to it.
// Include it after Eigen: httplib pulls in <resolv.h>, whose `_res` macro
// breaks Eigen's headers.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include <httplib.h>

namespace g2p::test {

// A chat-completions server whose reply is scripted per test.
class FakeVlmServer {
 public:
  using Reply = std::function<void(int attempt, const nlohmann::json& request, httplib::Response& res)>;

  explicit FakeVlmServer(Reply reply) : reply_(std::move(reply)) {
    server_.Post("/v1/chat/completions", [this](const httplib::Request& req, httplib::Response& res) {
      const int attempt = attempts_++;
      authorization_ = req.get_header_value("Authorization");
      last_request_ = nlohmann::json::parse(req.body, nullptr, false);
      reply_(attempt, last_request_, res);
    });
    port_ = server_.bind_to_any_port("127.0.0.1");
    thread_ = std::thread([this] { server_.listen_after_bind(); });
    while (!server_.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ~FakeVlmServer() {
    server_.stop();
    thread_.join();
  }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/v1"; }
  int attempts() const { return attempts_; }
  const nlohmann::json& last_request() const { return last_request_; }
  const std::string& authorization() const { return authorization_; }

  static void answer(httplib::Response& res, const std::string& content) {
    res.set_content(nlohmann::json{{"choices", {{{"message", {{"role", "assistant"}, {"content", content}}}}}}}.dump(),
                    "application/nlohmann::json");
  }

 private:
  httplib::Server server_;
  Reply reply_;
  int port_ = 0;
  std::thread thread_;
  std::atomic<int> attempts_{0};
  nlohmann::json last_request_;
  std::string authorization_;
};

}  // namespace g2p::test
