#pragma once
// WorldData: the mutable state of a World, sized from its WorldModel and shared by its source files
// (world.cpp and the stage files beside it): per mannequin its MannequinData, per mocap source its
// SourceData, the physics runtime (PhysicsData), the scenario binding (ScenarioRun), the step's
// contacts, diagnostics and counters. Not installed: only libs/sim/src includes it.
#include "mannequin/sim/world.hpp"
#include "mannequin/sim/world_model.hpp"

#include "mannequin/balance/static_balance.hpp"
#include "mannequin/balance/variational_balance.hpp"
#include "mannequin/scenario/engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/constraints/swing_twist.hpp"
#include "mannequin/control/first_order.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::sim {

constexpr double kJumpTolerance = 0.05;  // m: noise of a tracked position over a frame (mocap_input.cpp)
constexpr double kCatchUpSpeed = 1.0;    // m/s: a target catching up with its body after a stream gap (drive_targets.cpp)

/// max over limited coordinates of how far q is past a limit (rad, >= 0): revolute coordinates against
/// their bounds, ball joints against their swing ellipse and twist range (diagnostics.cpp).
double worstLimitExcess(const skeleton::Model& model, const skeleton::VectorX& q);

/// The physics runtime of a World (built from WorldModel::physics by World::buildPhysics).
struct PhysicsData {
  collision::CollisionWorld cw;
  std::vector<int> cw_mannequin;                       // per mannequin: index in cw
  std::vector<std::unique_ptr<MannequinSystem>> systems;
  std::vector<std::unique_ptr<constraints::MannequinFrames>> frames;
  std::unique_ptr<constraints::ContactRows> contacts;
  std::vector<std::unique_ptr<constraints::JointLimitRows>> limits;  // per mannequin (joint_limits on)
  std::vector<std::unique_ptr<constraints::BalanceRows>> balance;    // per mannequin (distance; rows if balance_rows)
  std::vector<std::vector<math::Vector3>> support;     // per mannequin: foot–floor points (capacity preallocated)
  std::vector<constraints::RigidObject> objects;                    // systems nm + i
  std::vector<int> object_body;                        // per object: collision body id
  std::unique_ptr<constraints::HingeLimitRows> hinges;
  std::unique_ptr<constraints::GraspRows> grasps;
  std::unique_ptr<GuideRows> guides;
  struct GraspRecord {
    int object = -1, mannequin = -1;                   // −1: free slot
    int joint = -1;                                    // joint carrying the grasping frame
  };
  std::vector<GraspRecord> grasp_records;              // per constraints::GraspRows handle
  std::unique_ptr<constraints::ConstraintSolver> solver;
  collision::ContactSet set;
  int floor_body = -1;                                 // "scene/floor", −1 if none
  std::vector<int> body_mannequin;                     // per body: mannequin index or −1
  std::vector<int> body_object;                        // per body: object index or −1
  std::vector<char> body_is_foot;                      // per body: a foot segment ("foot*", "toes*")
  std::vector<char> stepping;                          // per mannequin: stage 1 succeeded this step
  balance::StaticBalanceSolver margin_solver;          // the force margins (one solver, reused)
  balance::StaticBalanceProblem margin_problem;
  std::vector<int> body_joint;                         // per body: the joint carrying a segment, −1 if not a segment
  /// The balance controller of one mannequin (PhysicsConfig::balance_controller).
  struct BalanceLoop {
    std::unique_ptr<balance::VariationalBalanceSolver> solver;
    balance::VariationalBalanceProblem problem;
    std::vector<char> taken;       // per driven frame: taken over (MannequinModel::balance_frames)
    skeleton::Data data;           // kinematics at q_b
    skeleton::VectorX q_b;         // the controller's own configuration: Algorithm 5 iterates on it
    bool driving = false;          // q_b exists and drives the frames and the posture
    double fraction = 0.0;         // of the margins asked for, the last solve held
    skeleton::VectorX k, b;        // joint coupling gains (nv; the root's 0)
    explicit BalanceLoop(const skeleton::Model& model) : data(model) {}
  };
  std::vector<BalanceLoop> balance_loops;              // per mannequin when the controller is on
  explicit PhysicsData(const collision::WorldOptions& o) : cw(o) {}
  /// Whether mannequin m holds object o (contacts between them are ignored).
  bool holds(int m, int o) const {
    for (const GraspRecord& g : grasp_records)
      if (g.mannequin == m && g.object == o) return true;
    return false;
  }
};

/// The state of a mocap source (WorldModel::sources): its frames, and the anchor of its capture clock to
/// the World clock.
struct SourceData {
  MocapBuffer buffer{2.0};
  bool anchored = false;
  bool gap = false;   // its newest frame is older than occlusion_hold (counted once per gap)
  bool back = false;  // frames came back after a gap or the clock was re-anchored: the next step starts the catch-up
  std::int64_t anchor_capture_ns = 0;
  std::uint64_t anchor_step = 0;
};

/// The state of a mannequin (WorldModel::mannequins).
struct MannequinData {
  std::unique_ptr<Stepper> stepper;         // its skeleton Data, q and q̇
  ControllerStepper* controller = nullptr;  // the stepper when it is a ControllerStepper (physics needs it), else nullptr
  std::vector<DrivenFrame> frames;          // per control frame
  std::vector<math::SE3> previous_targets;  // targets of the previous step (target twist)
  std::vector<bool> have_previous;
  std::vector<double> weights;  // current weights (rate-limited)
  // after a stream gap: the offset (world, m and rotation vector) of each target from its body, shrinking at kCatchUpSpeed
  std::vector<math::Vector3> catch_p, catch_r;
  bool calibrated = false;
  skeleton::VectorX q_posture;  // q_c: the posture target set at calibration
  bool holding_restored = false;  // restored calibrated, its source not anchored yet: holds the restored targets
};

/// A scenario in the loop: its engine, where its frames and objects are in this World.
struct ScenarioRun {
  std::unique_ptr<scenario::Engine> engine;
  struct Frame {
    int mannequin = -1;
    std::size_t driven = 0;  // index in the mannequin's DrivenFrames
    int joint = -1;          // the joint carrying the frame
    // per joint of the model: 1 if its segment's contacts push on this frame — the joints whose nearest
    // control-frame joint up the tree (itself included) is this frame's (a foot's toes, a hand's fingers)
    std::vector<char> force_joints;
  };
  std::vector<Frame> frames;       // per scenario frame
  std::vector<int> objects;        // per scenario object: the World's object index
  std::vector<std::vector<int>> value_kind;  // per scenario object, per declared value: 0 angle, 1..3 x, y, z
  std::vector<int> grasp_handle;   // per scenario frame: its grasp (−1: none)
  std::vector<char> guided;        // per scenario object: 1 while a guide it attached holds it
  std::vector<const control::MechanismConfig*> mechanism;  // per scenario frame: the one its controller runs (into the engine's scenario)
  std::vector<scenario::Trigger> pending;
  scenario::Observation obs;
  long unapplied = 0;
};

/// Everything a World's step changes.
struct WorldData {
  std::vector<MannequinData> mannequins;  // per WorldModel::mannequins
  std::vector<SourceData> sources;        // per WorldModel::sources
  std::uint64_t steps = 0, failed_steps = 0;
  MocapGlitches glitches;
  std::vector<std::size_t> jumps;  // addMocap: the bodies of a frame that jumped (kept: no allocation per frame)
  std::unique_ptr<ScenarioRun> scenario;
  std::unique_ptr<PhysicsData> physics;
  StepDiagnostics diagnostics;
  std::vector<MannequinDiagnostics> mannequin_diagnostics;  // per mannequin
  std::vector<ContactReport> contacts;                      // the last step's
};

}  // namespace mannequin::sim
