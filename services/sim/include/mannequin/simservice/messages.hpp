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

}  // namespace mannequin::simservice
