#include "mannequin/transport/log_limiter.hpp"

#include <spdlog/spdlog.h>

#include "mannequin/transport/clock.hpp"

namespace mannequin::transport {

bool LogLimiter::warn(const std::string& key, const std::string& message) {
  Entry& e = entries_[key];
  const std::int64_t now = steadyNs();
  if (e.logged && now - e.last_ns < period_ns_) {
    ++e.suppressed;
    ++suppressed_total_;
    return false;
  }
  if (e.suppressed > 0)
    spdlog::warn("{} ({} similar suppressed)", message, e.suppressed);
  else
    spdlog::warn("{}", message);
  e.logged = true;
  e.last_ns = now;
  e.suppressed = 0;
  return true;
}

}  // namespace mannequin::transport
