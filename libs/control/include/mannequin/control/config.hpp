#pragma once
/// \file config.hpp
/// \brief The controller's configuration (configs/control/*.yaml; reference in docs/control.md).
///
/// Units: SI inside, angles in degrees in files (rpy_deg). Stiffness and damping 6-vectors are
/// ordered like twists, (rotation x y z, translation x y z), in CONTROL-FRAME axes:
/// N·m/rad and N/m for stiffness, N·m·s/rad and N·s/m for damping.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/control/energy.hpp"
#include "mannequin/control/projector.hpp"
#include "mannequin/control/virtual_mechanism.hpp"
#include "mannequin/core/config.hpp"

namespace mannequin::control {

/// A virtual mechanism attached to a control frame, with the coupling to its effector.
struct MechanismConfig {
  MechanismSpec spec;
  Vector6 stiffness = Vector6::Constant(0.0);  ///< coupling control frame ↔ effector (effector axes)
  Vector6 damping = Vector6::Constant(0.0);
  bool enabled = false;                        ///< switched on at start (else attach it at run time)
};

/// One control frame and its coupling to its target (2.12).
struct ControlFrameConfig {
  std::string name;                              ///< unique name (hand_r, ...)
  std::string frame;                             ///< model frame, or segment name (its frame)
  SE3 offset;                                    ///< control frame in that frame
  Vector6 stiffness = Vector6::Zero();           ///< k_c per axis (see file comment)
  Vector6 damping = Vector6::Zero();             ///< b_c per axis
  int priority = 0;                              ///< 0 = highest; equal levels are weighted (2.55–2.57)
  double weight = 1.0;                           ///< multiplies stiffness and damping
  bool enabled = true;
  std::optional<MechanismConfig> mechanism;
  std::string where;                             ///< "FILE:LINE" of its entry, for error messages
};

/// Joint viscous friction b_a (2.4), diagonal SPD, per velocity coordinate.
struct FrictionConfig {
  double root_linear = 300.0;   ///< N·s/m on the root's body linear velocity
  double root_angular = 60.0;   ///< N·m·s/rad on the root's body angular velocity
  double joints = 5.0;          ///< N·m·s/rad on every other coordinate
  std::map<std::string, double> coordinates;  ///< overrides by coordinate name ("knee_l", "hip_l.y")
};

enum class InternalProjection { kNone, kDynamic };

/// Internal (posture) control Γ_int = α Πᵀ(k_int(q_d − q) + b_int(q̇_d − q̇)) (2.25).
struct InternalConfig {
  bool enabled = true;
  double stiffness = 100.0;      ///< k_int, N·m/rad, every non-root coordinate
  double damping = 0.0;          ///< b_int, N·m·s/rad (explicit, previous q̇; keep below b_a)
  std::map<std::string, double> coordinates;  ///< k_int overrides by coordinate name
  std::string posture = "standing";           ///< q_d: "standing" or "neutral"
  InternalProjection projection = InternalProjection::kDynamic;  ///< "dynamic" (2.21–2.25) or "none"
  EnergyObserverOptions observer;
};

struct ControllerConfig {
  double dt = 1e-3;                                  ///< δt (s)
  Vector3 gravity = Vector3(0, 0, -9.81);            ///< m/s², world
  FrictionConfig b_a;
  InternalConfig internal;
  ProjectorMethod projector = ProjectorMethod::kLdlt;
  CouplingError coupling_error = CouplingError::kR3SO3;  ///< "r3_so3" (default) or "se3" (log(H⁻¹H_d))
  double rank_tolerance = 1e-9;                      ///< relative, on eigenvalues of J b_a⁻¹ Jᵀ
  std::vector<ControlFrameConfig> frames;
  std::string source;                                ///< file it came from (for messages)
};

/// Parses YAML text; `source` names it in errors. Checks everything that does not need the model
/// (the Controller checks names against the model); unknown keys are refused.
/// \throws core::ConfigError "SOURCE:LINE: field 'a.b': message".
ControllerConfig parseControllerConfig(const std::string& yaml_text, const std::string& source);
/// Reads and parses a file. \throws core::ConfigError (unreadable file included, line 0).
ControllerConfig loadControllerConfig(const std::string& path);

/// Parses one mechanism block (the `mechanism:` map of a control frame; also used by scenario
/// files). \throws core::ConfigError "SOURCE:LINE: field 'a.b': message".
MechanismConfig parseMechanismConfig(const std::string& yaml_text, const std::string& source);
/// The same for a block inside another file (errors name that file, its lines and the block's path).
MechanismConfig parseMechanismConfig(const core::ConfigNode& node);

}  // namespace mannequin::control
