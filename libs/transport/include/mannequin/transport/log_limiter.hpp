#pragma once
/// \file log_limiter.hpp
/// \brief Rate-limited warnings: at most one line per key per period, with the count suppressed
/// since the last line (so a flood of malformed messages cannot flood the log or slow the loop).
#include <cstdint>
#include <string>
#include <unordered_map>

namespace mannequin::transport {

class LogLimiter {
 public:
  explicit LogLimiter(double period_s = 1.0) : period_ns_(static_cast<std::int64_t>(period_s * 1e9)) {}

  /// Logs `message` as a spdlog warning under `key` unless one was logged less than a period ago
  /// (then only counts it). Returns true when it logged.
  bool warn(const std::string& key, const std::string& message);
  /// Lines suppressed since start (all keys).
  std::uint64_t suppressed() const { return suppressed_total_; }

 private:
  struct Entry {
    std::int64_t last_ns = 0;
    std::uint64_t suppressed = 0;
    bool logged = false;
  };
  std::int64_t period_ns_;
  std::unordered_map<std::string, Entry> entries_;
  std::uint64_t suppressed_total_ = 0;
};

}  // namespace mannequin::transport
