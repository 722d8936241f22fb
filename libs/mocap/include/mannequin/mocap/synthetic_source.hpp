#pragma once
/// \file synthetic_source.hpp
/// \brief Scripted trajectories (tests, scripted actors of the demonstrations): each body moves as
/// p(t) = center + amplitude ∘ sin(2π f t + phase) (component-wise), or through WAYPOINTS: from one to the
/// next along a straight line with the minimum-jerk time law s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (τ the fraction of
/// the segment's time; the body rests at each waypoint), holding the first before it and the last after
/// it; the orientation turns from one waypoint's to the next's along the geodesic, R_i exp(s log(R_iᵀ R_i+1)).
/// Otherwise the orientation is constant, or rotating about z at `yaw_rate`. Bodies can be occluded over
/// time windows.
#include <string>
#include <vector>

#include "mannequin/mocap/source.hpp"

namespace mannequin::mocap {

struct Waypoint {
  double t = 0.0;                             ///< s of capture time
  math::Vector3 p = math::Vector3::Zero();   ///< m, room frame
  math::Matrix3 R = math::Matrix3::Identity();  ///< orientation (room frame), reached with the same time law
};

struct SyntheticBody {
  std::string name;
  std::vector<Waypoint> waypoints;                  ///< non-empty: replaces center/amplitude (times increasing)
  math::Vector3 center = math::Vector3::Zero();     ///< m, room frame
  math::Vector3 amplitude = math::Vector3::Zero();  ///< m
  double frequency = 0.0;                           ///< Hz
  double phase = 0.0;                               ///< rad
  math::Matrix3 orientation = math::Matrix3::Identity();
  double yaw_rate = 0.0;                            ///< rad/s about the room z axis
};

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
  /// \throws std::invalid_argument for a rate <= 0, no bodies, waypoints not strictly increasing in time
  /// or not finite (naming the body).
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
