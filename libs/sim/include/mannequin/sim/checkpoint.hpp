#pragma once
/// \file checkpoint.hpp
/// \brief A World's state as a restarted sim puts it back (World::checkpoint, World::restore).
#include <cstdint>
#include <string>
#include <vector>

#include "mannequin/math/se3.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::sim {

/// A World's state as a restarted sim puts it back (World::checkpoint, World::restore; the sim service
/// keeps one in its checkpoint file, simservice/checkpoint.hpp). Velocities are not part of it: what is
/// restored starts at rest.
struct MannequinCheckpoint {
  std::string name;                 ///< instance name
  std::string model;                ///< skeleton::Model::name (a restore into another model is refused)
  skeleton::VectorX q;              ///< configuration (nq): root (p, rotation vector) then joints
  bool calibrated = false;
  skeleton::VectorX q_posture;      ///< q_c, the posture target set at calibration (nq; calibrated only)
  /// A driven control frame's calibration (calibrated only; every driven frame, any order).
  struct Frame {
    std::string frame, body;
    math::SE3 offset;               ///< bMf
    math::SE3 target;               ///< world: the last target (held until the mocap drives it again)
    double weight = 1.0;            ///< in [0, 1]
  };
  std::vector<Frame> frames;
};

/// A movable object's pose (PhysicsConfig scene objects).
struct ObjectCheckpoint {
  std::string name;
  bool hinged = false;
  math::SE3 pose;                   ///< world (free body)
  double angle = 0.0;               ///< rad (hinged)
};

struct WorldCheckpoint {
  std::uint64_t step = 0;           ///< step count (the World's time = step · δt)
  std::vector<MannequinCheckpoint> mannequins;  ///< every mannequin of the World, any order
  std::vector<ObjectCheckpoint> objects;        ///< every object of the World, any order
};

}  // namespace mannequin::sim
