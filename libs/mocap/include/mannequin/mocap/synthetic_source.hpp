#pragma once
/// \file synthetic_source.hpp
/// \brief Scripted trajectories for tests: each body moves as p(t) = center + amplitude ∘ sin(2π f t + phase)
/// (component-wise) with a constant orientation, or rotates about z at `yaw_rate`; bodies can be occluded
/// over time windows. Key frames (`keys`) add a scripted offset: the offset of the last key at or before t,
/// eased (smoothstep) towards the next key's; the first key's offset before it, the last's after it.
#include <string>
#include <utility>
#include <vector>

#include "mannequin/mocap/source.hpp"

namespace mannequin::mocap {

struct SyntheticBody {
  std::string name;
  math::Vector3 center = math::Vector3::Zero();     ///< m, room frame
  math::Vector3 amplitude = math::Vector3::Zero();  ///< m
  double frequency = 0.0;                           ///< Hz
  double phase = 0.0;                               ///< rad
  math::Matrix3 orientation = math::Matrix3::Identity();
  double yaw_rate = 0.0;                            ///< rad/s about the room z axis
  /// (time s, offset m) key frames added to the position, times strictly increasing; empty: none.
  std::vector<std::pair<double, math::Vector3>> keys;
};

/// The key frames' offset at time t (zero without keys).
math::Vector3 keyOffset(const std::vector<std::pair<double, math::Vector3>>& keys, double t);

struct Occlusion {
  std::string body;
  double from = 0.0, to = 0.0;  ///< capture time window [from, to) in s
};

struct SyntheticOptions {
  double rate_hz = 120.0;
  double duration = 0.0;  ///< s of capture, 0 = endless
  bool paced = true;
  std::vector<SyntheticBody> bodies;
  std::vector<Occlusion> occlusions;
};

class SyntheticSource final : public Source {
 public:
  /// \throws std::invalid_argument for a rate <= 0 or no bodies.
  explicit SyntheticSource(SyntheticOptions options);
  std::optional<Frame> next(std::chrono::microseconds timeout) override;
  bool finished() const override { return finished_; }
  std::string kind() const override { return "synthetic"; }
  std::string describe() const override;
  /// The frame at index k (time k / rate_hz).
  Frame frameAt(std::uint64_t k) const;

 private:
  SyntheticOptions options_;
  std::uint64_t k_ = 0;
  bool started_ = false, finished_ = false;
  std::int64_t start_ns_ = 0;
};

}  // namespace mannequin::mocap
