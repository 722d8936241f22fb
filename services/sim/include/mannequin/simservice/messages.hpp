#pragma once
/// \file messages.hpp
/// \brief The World's state and collision query as mannequin.v1 messages (mocap frames: transport/convert.hpp).
#include <mannequin/v1/collision.pb.h>
#include <mannequin/v1/mocap.pb.h>
#include <mannequin/v1/scenario.pb.h>
#include <mannequin/v1/world.pb.h>

#include "mannequin/scenario/engine.hpp"
#include "mannequin/sim/world.hpp"

namespace mannequin::simservice {

/// The World's state (header.stamp_ns = simulation time; the publisher fills the rest). `contacts`
/// (may be null): the contact set in use, with `stale` when it is older than its deadline.
void toWorldState(const sim::World& world, const v1::ContactSet* contacts, bool stale, bool replay, v1::WorldState& out);

/// The collision query of the current step (every mannequin's configuration).
void toCollisionQuery(const sim::World& world, double margin, v1::CollisionQuery& out);

/// The scenario's state (header.stamp_ns = simulation time): name, state, time in state, context stack,
/// the labels of the transitions fired at the last switch.
void toScenarioState(const scenario::Engine& engine, double sim_time, v1::ScenarioState& out);

/// Watches the World's scenario after each step (the sim service and mannequin-simulate): whether it
/// switched state, and whether scenario.state is due (`state_rate` per second of sim time, and at every
/// switch).
class ScenarioWatch {
 public:
  ScenarioWatch(double state_rate, double step) : per_step_(state_rate * step) {}
  struct Tick {
    const scenario::Engine* engine = nullptr;  ///< nullptr: no scenario, or not running yet (not calibrated)
    bool switched = false;  ///< entered a state this step (the initial one included)
    bool first = false;     ///< that state is the initial one
    bool publish = false;   ///< scenario.state is due
  };
  Tick after(const sim::World& world);
  /// The labels of the transitions fired at the engine's last switch, joined by "; ".
  static std::string events(const scenario::Engine& engine);

 private:
  double per_step_, phase_ = 0.0;
  int last_state_ = -1;
};

}  // namespace mannequin::simservice
