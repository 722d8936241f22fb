#pragma once
/// \file world_model.hpp
/// \brief The constant description of a World (as Pinocchio's Model is to its Data): built once by
/// buildWorldModel() from the mannequins' setups and the SimConfig, checked there, and never changed by
/// stepping. What stepping changes — per mannequin its stepper (skeleton Data, q, q̇), driven frames,
/// weights and catch-up offsets; per mocap source its buffer and clock anchor; the physics runtime
/// (collision world, row producers, objects, grasps); contacts, diagnostics and glitch counters — is the
/// World's WorldData, sized from this model (libs/sim/src/world_state.hpp).
///
/// Indices: a mannequin is its index in `mannequins`, a mocap source its index in `sources` ("" first),
/// a control frame its index in MannequinModel::control_frames (the same as in World::controlFrames()).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mannequin/collision/scene.hpp"
#include "mannequin/collision/world.hpp"
#include "mannequin/constraints/contacts.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/math/types.hpp"
#include "mannequin/sim/config.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::sim {

/// One mannequin of a World.
struct MannequinModel {
  std::string name;                              ///< instance name (unique in the World)
  skeleton::Model model;
  std::vector<ControlFrameSpec> control_frames;  ///< the frames its mocap bodies drive
  std::vector<int> frame_indices;                ///< per control frame: its model frame index
  int root_frame = -1;                           ///< model frame placed under its body at calibration (−1: none)
  int source = 0;                                ///< its mocap source: index in WorldModel::sources
  skeleton::VectorX q_standing;                  ///< skeleton::standingConfiguration(model)
  /// The controller's config (a ControllerStepper), gravity replaced by physics.gravity when physics is
  /// on; empty: the KinematicTracker with SimConfig::gains.
  std::optional<control::ControllerConfig> controller;
  /// The control frames the balance controller takes over (BalanceControllerConfig::frames, in its
  /// order), as indices in `control_frames`; empty when the balance controller is off.
  std::vector<int> balance_frames;
};

/// The physics scene of a World (PhysicsConfig::enabled), as the collision world and the contact rows
/// are built from it.
struct PhysicsModel {
  /// The scene, its activation distance the physics' (PhysicsConfig::activation_distance).
  collision::SceneSpec scene;
  /// Per mannequin: its segments' collision options (name, margin, self collision); `exclude_pairs`
  /// holds the segment pairs already within the activation distance of each other in its standing
  /// configuration (thighs side by side, arms along the trunk: docs/constraints.md).
  std::vector<collision::MannequinOptions> mannequin_options;
  /// Contact materials: the scene's default first, then the scene bodies', then the segments'.
  std::vector<std::string> materials;
  int segment_material = 0;                      ///< index in `materials`
  /// The contact rows' options, μ per material pair (materials × materials) from the scene's table
  /// (default_mu elsewhere).
  constraints::ContactOptions contacts;
  /// Index of a material in `materials` (−1: none).
  int material(const std::string& name) const;
};

struct WorldModel {
  SimConfig config;
  std::vector<std::string> sources;              ///< mocap sources, "" first
  std::vector<MannequinModel> mannequins;
  std::optional<PhysicsModel> physics;           ///< set when config.physics.enabled

  /// Index of the mannequin named `name`, −1 if none.
  int findMannequin(const std::string& name) const;
  /// Index of the mocap source `name`, −1 if none.
  int findSource(const std::string& name) const;
};

/// Checks the setups and the config and builds the model of their World.
/// \throws std::invalid_argument naming what is wrong and where: a step ≤ 0, two mannequins with the
/// same name, a control frame the model lacks (with the model's frames), and with physics on a
/// mannequin without a controller, a non-finite or out-of-range physics or balance-controller setting,
/// or a balance-controller frame that is not driven. (A controller config the controller refuses is
/// met when the World builds its steppers.)
WorldModel buildWorldModel(std::vector<MannequinSetup> setups, const SimConfig& config);

}  // namespace mannequin::sim
