// The supervisor's parts without processes: the restart policy, liveness from heartbeats, the output.
#include <fmt/format.h>

#include <algorithm>

#include "mannequin/deploy/heartbeat_monitor.hpp"
#include "mannequin/deploy/restart_policy.hpp"
#include "mannequin/deploy/status_printer.hpp"
#include "mannequin/transport/clock.hpp"

namespace mannequin::deploy {

RestartTracker::Decision RestartTracker::onExit(bool clean, double ran_s) {
  if (ran_s >= options_.stable_after) {
    restarts_ = 0;
    backoff_ = 0;
  }
  const bool restart = options_.policy == RestartPolicy::kAlways || (options_.policy == RestartPolicy::kOnFailure && !clean);
  if (!restart) return clean ? Decision::kFinished : Decision::kFailed;
  if (restarts_ >= options_.max_restarts) return Decision::kFailedPermanently;
  backoff_ = backoff_ == 0 ? options_.backoff_initial : std::min(options_.backoff_max, 2 * backoff_);
  return Decision::kRestart;
}

ServiceState liveness(bool has_heartbeat, std::int64_t last_heartbeat_ns, std::int64_t started_ns, std::int64_t now_ns,
                      double timeout_s) {
  if (has_heartbeat) return static_cast<double>(now_ns - last_heartbeat_ns) * 1e-9 > timeout_s ? ServiceState::kLate : ServiceState::kUp;
  return static_cast<double>(now_ns - started_ns) * 1e-9 > timeout_s ? ServiceState::kLate : ServiceState::kStarting;
}

HeartbeatMonitor::HeartbeatMonitor(zmq::context_t& context, const std::vector<std::string>& endpoints,
                                   std::optional<transport::CurveClientOptions> curve) {
  transport::SubscriberOptions so;
  so.name = "launch";
  so.curve = std::move(curve);
  subscriber_ = std::make_unique<transport::Subscriber>(context, so);
  for (const std::string& e : endpoints) subscriber_->connect(e);
  subscriber_->subscribe(transport::topics::kHeartbeat, std::function<void(const v1::Heartbeat&)>([this](const v1::Heartbeat& hb) {
                           if (target_ == nullptr) return;
                           for (ServiceStatus& st : *target_)
                             if (st.name == hb.service() || st.name == hb.header().source()) {
                               st.has_heartbeat = true;
                               st.last_heartbeat_ns = transport::steadyNs();
                               st.heartbeat = hb;
                               ++st.heartbeats;
                             }
                         }));
}

void HeartbeatMonitor::poll(std::vector<ServiceStatus>& status) {
  target_ = &status;
  subscriber_->poll(std::chrono::microseconds(0));
  target_ = nullptr;
}

void StatusPrinter::clear() {
  if (tty_ && shown_) {
    std::fputs("\r\033[K", out_);
    std::fflush(out_);
    shown_ = false;
  }
}

void StatusPrinter::line(const std::string& name, const std::string& text) {
  clear();
  const std::string s = fmt::format("{:<{}} | {}\n", name, width_, text);
  std::fwrite(s.data(), 1, s.size(), out_);
  std::fflush(out_);
}

void StatusPrinter::status(const std::string& text) {
  if (tty_) {
    clear();
    std::fwrite(text.data(), 1, text.size(), out_);
    std::fflush(out_);
    shown_ = true;
  } else {
    line("status", text);
  }
}

}  // namespace mannequin::deploy
