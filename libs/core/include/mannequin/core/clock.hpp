#pragma once
/// \file clock.hpp
/// \brief The two clocks of the cluster, in integer nanoseconds.
#include <chrono>
#include <cstdint>

namespace mannequin::core {

/// Wall clock (CLOCK_REALTIME), ns since the Unix epoch: Header.send_time_ns, comparable across hosts
/// synchronised by NTP/PTP.
inline std::int64_t wallNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// Monotonic clock (CLOCK_MONOTONIC), ns: loop pacing and rates inside one process.
inline std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace mannequin::core
