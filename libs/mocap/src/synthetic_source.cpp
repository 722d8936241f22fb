#include "mannequin/mocap/synthetic_source.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "mannequin/math/so3.hpp"
#include "mannequin/core/clock.hpp"

namespace mannequin::mocap {

math::Vector3 keyOffset(const std::vector<std::pair<double, math::Vector3>>& keys, double t) {
  if (keys.empty()) return math::Vector3::Zero();
  if (t <= keys.front().first) return keys.front().second;
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (t < keys[i].first) {
      const double s = (t - keys[i - 1].first) / (keys[i].first - keys[i - 1].first);
      return keys[i - 1].second + s * s * (3 - 2 * s) * (keys[i].second - keys[i - 1].second);
    }
  return keys.back().second;
}

SyntheticSource::SyntheticSource(SyntheticOptions options) : options_(std::move(options)) {
  if (!(options_.rate_hz > 0)) throw std::invalid_argument("synthetic: rate_hz must be > 0");
  if (options_.bodies.empty()) throw std::invalid_argument("synthetic: no bodies");
  for (const SyntheticBody& b : options_.bodies)
    for (std::size_t i = 1; i < b.keys.size(); ++i)
      if (!(b.keys[i].first > b.keys[i - 1].first))
        throw std::invalid_argument("synthetic: body '" + b.name + "': key times must increase");
  for (const Occlusion& o : options_.occlusions) {
    bool known = false;
    for (const auto& b : options_.bodies) known = known || b.name == o.body;
    if (!known) throw std::invalid_argument("synthetic: occlusion of unknown body '" + o.body + "'");
  }
}

std::string SyntheticSource::describe() const {
  return fmt::format("synthetic trajectories ({} bodies at {} Hz{})", options_.bodies.size(), options_.rate_hz,
                     options_.duration > 0 ? fmt::format(" for {} s", options_.duration) : std::string());
}

Frame SyntheticSource::frameAt(std::uint64_t k) const {
  const double t = static_cast<double>(k) / options_.rate_hz;
  Frame s;
  s.frame_number = k;
  s.stamp_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
  s.calibration_pose = k == 0;
  for (std::size_t i = 0; i < options_.bodies.size(); ++i) {
    const SyntheticBody& sb = options_.bodies[i];
    Body b;
    b.name = sb.name;
    b.id = static_cast<int>(i);
    const double w = 2 * M_PI * sb.frequency * t + sb.phase;
    b.pose.p = sb.center + sb.amplitude * std::sin(w) + keyOffset(sb.keys, t);
    b.pose.R = math::expSO3(math::Vector3(0, 0, sb.yaw_rate * t)) * sb.orientation;
    for (const Occlusion& o : options_.occlusions)
      if (o.body == sb.name && t >= o.from && t < o.to) b.tracked = false;
    if (!b.tracked) b.quality = 0.0;
    s.bodies.push_back(b);
  }
  return s;
}

std::optional<Frame> SyntheticSource::next(std::chrono::microseconds timeout) {
  if (finished_) return std::nullopt;
  if (options_.duration > 0 && static_cast<double>(k_) / options_.rate_hz > options_.duration) {
    finished_ = true;
    return std::nullopt;
  }
  if (options_.paced) {
    if (!started_) {
      started_ = true;
      start_ns_ = core::steadyNs();
    }
    const auto due = start_ns_ + static_cast<std::int64_t>(static_cast<double>(k_) / options_.rate_hz * 1e9);
    if (!sleepUntil(due, timeout)) return std::nullopt;
  }
  return frameAt(k_++);
}

}  // namespace mannequin::mocap
