#pragma once
/// \file engine.hpp
/// \brief The scenario's state machine (thesis 4.1.2): per step it reads the observations, evaluates the
/// current state's transitions (and the scenario's interrupts), runs the phases of the states it leaves
/// and enters, hands the entry/exit actions to the caller and gives each control frame its mode and a
/// velocity-continuous setpoint (Fig. 4.5).
///
/// Phases of a state: configure (a fresh entry: goals relative to objects are resolved, entry actions
/// emitted), start (each time the state becomes active, fresh or resumed: modes commanded, continuity
/// trajectories built from the current setpoints), run (every step it is active: transitions
/// evaluated), teardown (a real exit: exit actions emitted). An urgent transition suspends the current
/// state (no teardown) and pushes it on the context stack; `resume` tears the interrupting state down
/// and restarts the suspended one (start only, its time in state kept).
///
/// Deterministic: the same observations give the same outputs. At most one transition fires per step
/// (interrupts first, then the state's transitions in file order). No heap allocation in step() after
/// the first one, switches included (tested), except for copying the names of undeclared triggers.
#include <string>
#include <vector>

#include "mannequin/control/virtual_mechanism.hpp"
#include "mannequin/scenario/scenario.hpp"
#include "mannequin/scenario/trajectory.hpp"

namespace mannequin::scenario {

/// What the engine sees of one control frame.
struct FrameObservation {
  SE3 pose;                          ///< the simulated control frame, world (zones, distances, reached)
  SE3 target;                        ///< its mocap target, world (free follows it, constrained projects it)
  Vector3 force = Vector3::Zero();   ///< contact / hand force on it (N, world)
};

struct ObjectObservation {
  SE3 pose;                    ///< world
  std::vector<double> values;  ///< the object's declared values, in declaration order
};

/// An operator trigger (scenario.proto Trigger).
struct Trigger {
  std::string name;
  std::string value;
};

/// One step's observations; vectors in the scenario's order (Scenario::frames, Scenario::objects).
struct Observation {
  double time = 0;  ///< sim time (s), non-decreasing
  std::vector<FrameObservation> frames;
  std::vector<ObjectObservation> objects;
  std::vector<Trigger> triggers;  ///< received since the previous step
};

enum class Phase { kConfigure, kStart, kRun, kTeardown };
const char* toString(Phase phase);

/// An action for the caller, in the order to apply it (exit actions of the state left, then entry
/// actions of the state entered).
struct ActionCommand {
  const Action* action = nullptr;  ///< into the engine's scenario
  int state = -1;                  ///< the state whose entry/exit it is
  bool entry = true;
};

/// The command of one control frame this step.
struct FrameCommand {
  ControlMode mode = ControlMode::kFree;
  const ModeSpec* spec = nullptr;  ///< into the engine's scenario
  Setpoint setpoint;               ///< velocity-continuous across switches
  SE3 goal;                        ///< autonomous: the goal, world (resolved at configure)
  bool blending = false;           ///< a continuity trajectory is still running
};

struct StepResult {
  bool switched = false;
  std::vector<ActionCommand> actions;
  std::vector<std::pair<int, Phase>> phases;  ///< (state, phase) run this step, in order
  std::vector<FrameCommand> frames;           ///< per control frame
  std::vector<std::string> unknown_triggers;  ///< received but not declared (ignored)
};

class Engine {
 public:
  explicit Engine(Scenario scenario);

  /// One step. \throws std::invalid_argument when the observation's sizes do not match the scenario or
  /// its time is earlier than the previous step's (NaN included).
  const StepResult& step(const Observation& obs);

  const Scenario& scenario() const { return s_; }
  int state() const { return state_; }
  const std::string& stateName() const { return s_.states[static_cast<std::size_t>(state_)].name; }
  double timeInState() const { return time_in_state_; }
  /// Suspended states, oldest first (ScenarioState.context_stack).
  std::vector<std::string> contextStack() const;
  /// Labels of the transitions fired at the last switch (ScenarioState.last_events).
  std::vector<std::string> lastEvents() const;

 private:
  struct Context {
    int state;
    double time_in_state;
  };
  struct FrameState {
    Setpoint setpoint;             ///< last output
    SE3 prev_target;               ///< previous observation's mocap target
    bool has_setpoint = false;
    MinimumJerkTrajectory trajectory;
    double start_time = 0;         ///< of the trajectory / blend
    Blend blend;
    bool blending = false;
    SE3 goal;
  };

  bool eval(const Condition& c, const Observation& obs) const;
  void enter(int state, const Observation& obs, bool fresh, double time_in_state);
  void leave(bool teardown);
  Setpoint rawSetpoint(std::size_t f, const SE3& target) const;  ///< the current mode's own setpoint
  Setpoint modeSetpoint(std::size_t f, const Observation& obs, double dt) const;

  Scenario s_;
  /// mechanisms_[state][frame]: the constrained modes' mechanisms, built once
  std::vector<std::vector<std::unique_ptr<control::VirtualMechanism>>> mechanisms_;
  std::vector<const Condition*> edge_conditions_;
  std::vector<char> inside_prev_, inside_now_;
  std::vector<FrameState> frames_;
  std::vector<Context> stack_;
  std::vector<const Transition*> last_events_;  ///< into s_ (no copy per switch)
  StepResult result_;
  int state_ = -1;
  double active_since_ = 0, time_offset_ = 0, time_in_state_ = 0, prev_time_ = 0;
  bool started_ = false;
};

}  // namespace mannequin::scenario
