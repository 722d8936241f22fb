#pragma once
/// \file scenario.hpp
/// \brief A scenario (thesis 4.1.2): the finite-state machine of command modes, as data, and its loader
/// (configs/scenarios/*.yaml; reference in docs/scenario.md).
///
/// A state gives each control frame a mode — free (follows mocap), constrained (a virtual mechanism),
/// autonomous (a minimum-jerk trajectory to a goal) —, entry/exit actions, and transitions on events.
/// Names match proto/mannequin/v1/scenario.proto (ControlMode FREE/CONSTRAINED/AUTONOMOUS).
/// Everything is checked at load: every error is a core::ConfigError "FILE:LINE: field 'a.b': reason".
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/control/config.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/math/se3.hpp"

namespace mannequin::scenario {

using math::SE3;
using math::Vector3;
using math::Vector6;

/// The mode of one control frame (scenario.proto ControlMode).
enum class ControlMode { kFree, kConstrained, kAutonomous };
const char* toString(ControlMode mode);  ///< "free", "constrained", "autonomous"

/// One control frame the scenario commands: "mannequin.frame" in files (the bare frame name when
/// only one mannequin lists it).
struct FrameRef {
  std::string mannequin;
  std::string frame;
  std::string name() const { return mannequin + "." + frame; }
};

/// An object the scenario refers to (events on its pose or state values, grasp targets).
struct ObjectDecl {
  std::string name;
  std::vector<std::string> values;  ///< named state values (door angle, lever position), in observation order
};

/// Velocity profile of an autonomous trajectory (only minimum jerk for now).
enum class Profile { kMinimumJerk };

/// A frame's mode in a state.
struct ModeSpec {
  ControlMode mode = ControlMode::kFree;
  // constrained
  std::optional<control::MechanismConfig> mechanism;
  // autonomous
  SE3 goal;                 ///< world, or relative to `relative_to` (the object's pose at the state's configure)
  int relative_to = -1;     ///< object index, −1: world
  double duration = 1.0;    ///< s
  Profile profile = Profile::kMinimumJerk;
  /// Continuity (Fig. 4.5): time the setpoint takes to join this mode's own setpoint at a switch (s).
  double blend = 0.5;
  std::string where;        ///< FILE:LINE
};

/// An action run at a state's entry or exit, handed to the caller as a command.
struct Action {
  enum class Kind { kGrasp, kRelease, kAttachGuide, kDetachGuide, kSetGains };
  Kind kind = Kind::kGrasp;
  int frame = -1;     ///< control frame index (grasp, release, set_gains)
  int object = -1;    ///< object index (grasp, release: optional, attach/detach_guide)
  std::optional<control::MechanismConfig> mechanism;  ///< attach_guide
  std::optional<Vector6> stiffness, damping;          ///< set_gains (rotation xyz, translation xyz)
  std::string where;
};
const char* toString(Action::Kind kind);  ///< "grasp", "release", "attach_guide", "detach_guide", "set_gains"

/// A zone in the world: a box (centre, half extents, rotation) or a sphere.
struct Zone {
  bool sphere = true;
  SE3 pose;                              ///< centre (and the box's axes)
  double radius = 0;                     ///< sphere
  Vector3 half_extents = Vector3::Zero();  ///< box
  bool contains(const Vector3& x) const;
};

/// An event condition: a tree whose leaves read the observations and whose inner nodes combine them.
struct Condition {
  enum class Kind {
    kInside, kOutside,   ///< the frame is in / out of the zone (level)
    kEnter, kLeave,      ///< the frame crossed the zone's boundary since the previous step (edge)
    kDistance,           ///< distance frame ↔ frame / object / point above or below a value
    kForce,              ///< norm of the frame's contact force above or below a value (N)
    kReached,            ///< the frame is within tolerance of a pose (default: its autonomous goal)
    kTime,               ///< time in state ≥ value (s)
    kObject,             ///< an object's state value above or below a value
    kTrigger,            ///< an operator trigger was received this step (optionally with a value)
    kAll, kAny, kNot
  };
  Kind kind = Kind::kTime;
  int frame = -1;
  int other_frame = -1, object = -1;  ///< distance to a frame / an object (else `point`)
  int value_index = -1;               ///< kObject: index into the object's values
  Vector3 point = Vector3::Zero();
  Zone zone;
  bool above = true;                  ///< compare: above (>) or below (<) `threshold`
  double threshold = 0;
  std::optional<SE3> pose;            ///< kReached: explicit pose (else the frame's autonomous goal)
  double tolerance_m = 0.01, tolerance_rad = 0.0872664626;
  std::string trigger, trigger_value; ///< kTrigger (empty value: any)
  int memory = -1;                    ///< kEnter/kLeave: slot of the previous inside flag
  std::vector<Condition> children;    ///< kAll, kAny, kNot (one)
  std::string where;
  /// Short text for graphs and last_events ("enter hand_r sphere", "trigger drill", "all(...)").
  std::string describe(const std::vector<FrameRef>& frames, const std::vector<ObjectDecl>& objects) const;
};

/// A transition: to a state, or back to the interrupted one (resume).
struct Transition {
  int to = -1;          ///< state index; −1 with resume
  bool resume = false;  ///< pop the context stack
  bool urgent = false;  ///< push the current state first (interrupt); resume returns to it
  std::string label;    ///< name: given in the file or the condition's description
  Condition when;
  std::string where;
};

struct State {
  std::string name;
  std::vector<ModeSpec> modes;  ///< per control frame (scenario frame order); unlisted frames are free
  std::vector<Action> entry, exit;
  std::vector<Transition> transitions;
  std::string where;
};

/// A problem that does not stop loading (an unreachable state).
struct Warning {
  std::string where;
  std::string message;
};

struct Scenario {
  std::string name;
  std::string source;                 ///< file
  std::vector<std::string> mannequins;
  std::vector<FrameRef> frames;       ///< the commanded control frames, in order
  std::vector<ObjectDecl> objects;
  std::vector<std::string> triggers;  ///< declared operator triggers
  int initial = 0;
  std::vector<State> states;
  std::vector<Transition> interrupts; ///< urgent transitions checked from every state
  int memory_slots = 0;               ///< edge conditions' memory (see Condition::memory)
  std::vector<Warning> warnings;

  int stateIndex(const std::string& name) const;   ///< −1 if absent
  int frameIndex(const std::string& name) const;   ///< "mannequin.frame" or a unique bare frame; −1
  int objectIndex(const std::string& name) const;  ///< −1 if absent
  int triggerIndex(const std::string& name) const; ///< −1 if absent
};

/// Parses YAML text; `source` names it in errors. \throws core::ConfigError "SOURCE:LINE: field 'a.b': reason".
Scenario parseScenario(const std::string& yaml_text, const std::string& source);
/// Reads and parses a file. \throws core::ConfigError.
Scenario loadScenario(const std::string& path);

}  // namespace mannequin::scenario
