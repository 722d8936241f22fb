#pragma once
/// \file heartbeat_monitor.hpp
/// \brief The services' health as their heartbeats tell it: subscribes to health.heartbeat on every
/// service's endpoint, records each one's last heartbeat, and says whether a running service is up
/// or late (liveness() is pure: unit-testable).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <zmq.hpp>

#include "mannequin/deploy/supervisor.hpp"
#include "mannequin/transport/subscriber.hpp"

namespace mannequin::deploy {

/// A running service's state from its heartbeats: up while the last one is younger than `timeout_s`;
/// late when it is older, or when none came within `timeout_s` of the start; starting before that.
ServiceState liveness(bool has_heartbeat, std::int64_t last_heartbeat_ns, std::int64_t started_ns, std::int64_t now_ns,
                      double timeout_s);

class HeartbeatMonitor {
 public:
  /// Connects to every endpoint (the address of a service), as a CURVE client when `curve` is set
  /// (Deployment::clientKeys: the launcher's key pair, every service's public key by its address).
  HeartbeatMonitor(zmq::context_t& context, const std::vector<std::string>& endpoints,
                   std::optional<transport::CurveClientOptions> curve = std::nullopt);
  /// Receives what arrived (non-blocking) into the statuses of the services it names (by service name
  /// or message source): has_heartbeat, last_heartbeat_ns, heartbeat, heartbeats.
  void poll(std::vector<ServiceStatus>& status);

 private:
  std::unique_ptr<transport::Subscriber> subscriber_;
  std::vector<ServiceStatus>* target_ = nullptr;
};

}  // namespace mannequin::deploy
