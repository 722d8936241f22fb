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

#include "mannequin/core/config.hpp"
#include "mannequin/mocap/frame.hpp"

namespace mannequin::mocap {

class Source {
 public:
  virtual ~Source() = default;
  /// Waits up to `timeout` for the next frame (live sources block on the network, file sources sleep
  /// until the frame is due when paced). nullopt: nothing (yet, or finished()).
  virtual std::optional<Frame> next(std::chrono::microseconds timeout) = 0;
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

/// Sleeps until the steady clock reaches `deadline_ns`, or `max_wait` elapsed. Returns true if reached.
bool sleepUntil(std::int64_t deadline_ns, std::chrono::microseconds max_wait);

}  // namespace mannequin::mocap
