#pragma once
/// \file mocap_buffer.hpp
/// \brief Recent mocap frames and the target of a body at any capture time: interpolated between the
/// two frames around it in R³×SO(3) (math::interpolate), held at the newest frame past it.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/math/se3.hpp"
#include "mannequin/mocap/frame.hpp"

namespace mannequin::sim {

/// A body's pose at a time, and whether it is tracked there.
struct BodySample {
  math::SE3 pose;
  bool tracked = false;
  std::int64_t last_tracked_ns = 0;  ///< capture time of the last frame where it was tracked
  bool ever_tracked = false;
};

class MocapBuffer {
 public:
  /// Keeps frames of the last `window_s` seconds of capture time.
  explicit MocapBuffer(double window_s = 1.0) : window_ns_(static_cast<std::int64_t>(window_s * 1e9)) {}
  /// Adds a frame. Frames whose stamp is not after the newest are ignored (returns false).
  bool add(const mocap::Frame& frame);
  /// The pose of `body` at capture time t_ns: interpolated between the frames around t when tracked
  /// in both, the tracked one of the two otherwise, the newest frame's (or last tracked) past the end.
  BodySample sample(const std::string& body, std::int64_t t_ns) const;
  const mocap::Frame* newest() const { return frames_.empty() ? nullptr : &frames_.back(); }
  std::size_t size() const { return frames_.size(); }
  void clear() { frames_.clear(); last_tracked_.clear(); }
  /// A restarted capture clock: drops the frames, keeps each body's last tracked pose as if seen at
  /// `stamp_ns` (so the occlusion hold starts again there), then adds `frame`.
  void restart(const mocap::Frame& frame);
  /// Capture-time span of the frames kept (ns).
  std::int64_t window_ns() const { return window_ns_; }

 private:
  struct LastTracked {
    std::string name;
    math::SE3 pose;
    std::int64_t stamp_ns = 0;
  };
  std::int64_t window_ns_;
  std::deque<mocap::Frame> frames_;
  std::vector<LastTracked> last_tracked_;
};

}  // namespace mannequin::sim
