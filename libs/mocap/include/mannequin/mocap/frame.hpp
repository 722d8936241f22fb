#pragma once
/// \file frame.hpp
/// \brief The one in-process mocap frame: named rigid bodies in the room frame (z up, metres) at a
/// capture time. Sources produce it, the sim World consumes it; v1::MocapFrame is its wire form
/// (transport/convert.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "mannequin/math/se3.hpp"

namespace mannequin::mocap {

/// One rigid body of a frame.
struct Body {
  std::string name;
  math::SE3 pose;       ///< body frame in the room frame (z up, m)
  bool tracked = true;  ///< false: occluded in this frame (pose = last tracked pose, or identity if never seen)
  double quality = 1.0; ///< [0, 1]
  int id = -1;          ///< source id (DTrack id, BVH joint index)
};

/// One frame of a source.
struct Frame {
  std::int64_t stamp_ns = 0;      ///< capture time in the source's clock
  std::uint64_t frame_number = 0;
  bool calibration_pose = false;  ///< the actor holds the calibration pose in this frame
  std::vector<Body> bodies;
  // Set by a receiver from the message header (0 at the source): which message carried the frame.
  std::uint64_t sequence = 0;     ///< Header.sequence
  std::int64_t send_time_ns = 0;  ///< Header.send_time_ns
};

}  // namespace mannequin::mocap
