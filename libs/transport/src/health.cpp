#include "mannequin/transport/health.hpp"

#include <unistd.h>

#include <algorithm>

#include "mannequin/transport/clock.hpp"

namespace mannequin::transport {

HealthReporter::HealthReporter(Publisher& publisher, std::string service, const Subscriber* subscriber, double period_s)
    : publisher_(publisher), subscriber_(subscriber), service_(std::move(service)), period_s_(period_s) {
  char host[256] = {};
  if (gethostname(host, sizeof(host) - 1) == 0) host_ = host;
  start_ns_ = period_start_ns_ = steadyNs();
}

void HealthReporter::lateness(double seconds) { worst_lateness_s_ = std::max(worst_lateness_s_, seconds); }

void HealthReporter::setState(v1::ServiceState state, std::string message) {
  state_ = state;
  message_ = std::move(message);
}

void HealthReporter::setStat(const std::string& name, double value) {
  for (auto& [n, v] : stats_)
    if (n == name) {
      v = value;
      return;
    }
  stats_.emplace_back(name, value);
}

v1::Heartbeat HealthReporter::snapshot() const {
  const std::int64_t now = steadyNs();
  const double dt = std::max(1e-9, (now - period_start_ns_) * 1e-9);
  v1::Heartbeat hb;
  hb.mutable_header()->set_stamp_ns(wallNs());
  hb.set_service(service_);
  hb.set_host(host_);
  hb.set_pid(static_cast<int>(getpid()));
  hb.set_state(state_);
  hb.set_loop_rate_hz(static_cast<double>(loops_ - loops_at_period_start_) / dt);
  hb.set_worst_lateness_ms(worst_lateness_s_ * 1e3);
  hb.set_uptime_s((now - start_ns_) * 1e-9);
  hb.set_message(message_);
  auto previous = [&](const std::string& key) -> std::uint64_t {
    for (const auto& [k, v] : messages_at_period_start_)
      if (k == key) return v;
    return 0;
  };
  auto add = [&](const TopicCounters& c, bool published) {
    if (c.topic == topics::kHeartbeat.name) return;
    v1::TopicCounters* t = hb.add_topics();
    t->set_topic(c.topic);
    t->set_published(published);
    t->set_messages(c.delivered);
    t->set_dropped(c.dropped + c.superseded);
    t->set_malformed(c.malformed);
    t->set_rate_hz(static_cast<double>(c.delivered - previous((published ? "p:" : "s:") + c.topic)) / dt);
  };
  for (const TopicCounters& c : publisher_.counters()) add(c, true);
  if (subscriber_ != nullptr)
    for (const TopicCounters& c : subscriber_->counters()) add(c, false);
  for (const auto& [n, v] : stats_) {
    v1::Stat* s = hb.add_stats();
    s->set_name(n);
    s->set_value(v);
  }
  return hb;
}

bool HealthReporter::tick(bool force) {
  const std::int64_t now = steadyNs();
  if (!force && (now - period_start_ns_) * 1e-9 < period_s_) return false;
  v1::Heartbeat hb = snapshot();
  hb.mutable_header()->set_stamp_ns(wallNs());
  publisher_.publish(topics::kHeartbeat, hb);
  // new period
  period_start_ns_ = now;
  loops_at_period_start_ = loops_;
  worst_lateness_s_ = 0.0;
  messages_at_period_start_.clear();
  for (const TopicCounters& c : publisher_.counters()) messages_at_period_start_.emplace_back("p:" + c.topic, c.delivered);
  if (subscriber_ != nullptr)
    for (const TopicCounters& c : subscriber_->counters()) messages_at_period_start_.emplace_back("s:" + c.topic, c.delivered);
  return true;
}

}  // namespace mannequin::transport
