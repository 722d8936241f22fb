#pragma once
/// \file source.hpp
/// \brief A motion-capture source: frames of named rigid bodies in the room frame (z up, metres),
/// with capture timestamps. BVH files, synthetic trajectories and ART DTrack2 live streams implement it.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <mannequin/v1/mocap.pb.h>

#include "mannequin/math/se3.hpp"
#include "mannequin/core/config.hpp"

namespace mannequin::mocap {

/// One rigid body of a frame.
struct Body {
  std::string name;
  int id = -1;          ///< source id (DTrack id, BVH joint index)
  math::SE3 pose;       ///< body frame in the room frame (z up, m)
  bool tracked = true;  ///< false: occluded in this frame (pose = last tracked pose, or identity if never seen)
  double quality = 1.0; ///< [0, 1]
};

/// One frame of a source.
struct Sample {
  std::int64_t stamp_ns = 0;    ///< capture time in the source's clock
  std::uint64_t frame_number = 0;
  bool calibration_pose = false;  ///< the actor holds the calibration pose in this frame
  std::vector<Body> bodies;
};

class Source {
 public:
  virtual ~Source() = default;
  /// Waits up to `timeout` for the next frame (live sources block on the network, file sources sleep
  /// until the frame is due when paced). nullopt: nothing (yet, or finished()).
  virtual std::optional<Sample> next(std::chrono::microseconds timeout) = 0;
  /// True when no frame will ever come again (end of a non-looping file).
  virtual bool finished() const = 0;
  /// "bvh", "synthetic", "dtrack2".
  virtual std::string kind() const = 0;
  /// Human-readable description for the start-up log.
  virtual std::string describe() const = 0;
};

/// Builds the source the config names (key `source`, and its section). See docs/cluster.md.
/// \throws core::ConfigError naming FILE:LINE and the field.
std::unique_ptr<Source> makeSource(const core::ConfigNode& config);

/// The MocapFrame of a sample (header.stamp_ns = capture time; the publisher fills the rest).
v1::MocapFrame toMessage(const Sample& sample, const std::string& kind);

/// Sleeps until the steady clock reaches `deadline_ns`, or `max_wait` elapsed. Returns true if reached.
bool sleepUntil(std::int64_t deadline_ns, std::chrono::microseconds max_wait);

}  // namespace mannequin::mocap
