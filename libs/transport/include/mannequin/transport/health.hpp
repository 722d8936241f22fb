#pragma once
/// \file health.hpp
/// \brief Heartbeats: every service publishes health.heartbeat (name, host, pid, state, loop rate,
/// worst lateness, per-topic counters, service statistics) every `period_s` on its own publisher.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"

namespace mannequin::transport {

class HealthReporter {
 public:
  /// `publisher` sends the heartbeats and its counters are reported; `subscriber` (optional) too.
  HealthReporter(Publisher& publisher, std::string service, const Subscriber* subscriber = nullptr,
                 double period_s = 0.5);

  /// One iteration of the service's main loop (counted for the loop rate).
  void loopIteration(std::uint64_t n = 1) { loops_ += n; }
  /// How late a loop deadline was (s); the worst of each period is reported.
  void lateness(double seconds);
  void setState(v1::ServiceState state, std::string message = {});
  v1::ServiceState state() const { return state_; }
  /// A service statistic (kept until changed; reported in every heartbeat).
  void setStat(const std::string& name, double value);
  /// Publishes a heartbeat if the period has elapsed (or `force`). Returns true when it published.
  bool tick(bool force = false);
  /// The heartbeat tick() would send now (without sending; rates over the current period).
  v1::Heartbeat snapshot() const;

 private:
  Publisher& publisher_;
  const Subscriber* subscriber_;
  std::string service_;
  std::string host_;
  double period_s_;
  v1::ServiceState state_ = v1::SERVICE_STATE_STARTING;
  std::string message_;
  std::vector<std::pair<std::string, double>> stats_;
  std::int64_t start_ns_, period_start_ns_;
  std::uint64_t loops_ = 0, loops_at_period_start_ = 0;
  double worst_lateness_s_ = 0.0;
  std::vector<std::pair<std::string, std::uint64_t>> messages_at_period_start_;
};

}  // namespace mannequin::transport
