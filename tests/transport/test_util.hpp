#pragma once
// Helpers of the transport tests: a unique ipc directory per test, and a pub/sub handshake.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"

namespace mannequin::transport::testing {

/// A fresh directory under the temp dir, removed at destruction; ipc("x") is an endpoint in it.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("mq-") + (info ? info->name() : "t") + "-" + std::to_string(getpid());
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string ipc(const std::string& name) const { return "ipc://" + (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Publishes a heartbeat and polls both sides until the subscriber has it (the late-joiner resend
/// makes this independent of connection timing). After it, every subscription of `sub` is in place.
inline bool handshake(Publisher& pub, Subscriber& sub, int max_ms = 5000) {
  bool got = false;
  sub.subscribe(topics::kHeartbeat, std::function<void(const v1::Heartbeat&)>([&](const v1::Heartbeat&) { got = true; }));
  v1::Heartbeat hb;
  hb.set_service("handshake");
  pub.publish(topics::kHeartbeat, hb);
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(max_ms);
  while (!got && std::chrono::steady_clock::now() < until) {
    pub.poll();
    sub.poll(std::chrono::milliseconds(2));
  }
  return got;
}

}  // namespace mannequin::transport::testing
