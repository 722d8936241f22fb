// bench-step: one step of the sim's World for the male_50th mannequin driven by the demo's six mocap
// bodies (pelvis, head, hands, feet), a new 120 Hz mocap frame every 8 or 9 steps of 1 ms, the hands
// moving on circles (0.2 m radius, 1 rev/s ≈ 1.3 m/s) and the pelvis swaying. Rows:
//   BM_WorldStep/controller   the ControllerStepper (configs/control/mocap.yaml, as the demo)
//   BM_WorldStep/controller_no_target_twist   the same without the targets' velocities fed forward
//   BM_WorldStep/kinematic    the KinematicTracker (damped least squares, SVD of the 36×43 Jacobian)
// Counters: hand_err_mm / pelvis_err_mm, the mean position error of the left hand and the pelvis over
// the run (how well each stepper follows the same motion), and the frame count.
//
// Physics in the loop (PhysicsConfig::enabled: collision query, controller free motion, one LCP of the
// contact and joint-limit rows, integration), the whole World step against the number of contact rows:
//   BM_PhysicsStep/contacts:N   the mannequin standing still (targets at the standing pose, mocap.yaml,
//       PhysicsConfig::gravity 0: contacts:0 has nothing to stand on) on the floor, with N − F small static
//       spheres (radius 15 mm) 1 mm (after margins) from its segments, frictionless (μ = 0 with skin: one
//       LCP row per contact; the feet keep their friction cones), F = the feet's floor rows (contacts:0 has
//       no floor). Rows within the activation distance, mostly λ = 0: the LCP
//       has them all, the active set is the feet's.
//   BM_PhysicsStep/standing_hands_on_table   configs/control/default.yaml, gravity on (PhysicsConfig), both hands on
//       two table tops (0.3 × 0.3 × 0.04 m boxes) under them, the hand targets 1 cm below the tops.
// Counters: contacts (mean contact rows per step, measured), active (λ > 0), lcp (LCP size), pivots,
// per-stage µs (collision, constraints, integrate), max_pen_mm, lcp_failures, failed_steps.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "bench_main.hpp"
#include "mannequin/collision/world.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {

const char* kBodies[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};

void worldStep(benchmark::State& state, bool controller, bool feed_forward) {
  MannequinSetup m;
  m.name = "operator";
  m.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  for (const char* b : kBodies) m.frames.push_back({b, b});
  if (controller) m.controller = control::loadControllerConfig(mannequin::bench::dataFile("configs/control/mocap.yaml"));
  skeleton::Data d(m.model);
  skeleton::forwardKinematics(m.model, d, skeleton::standingConfiguration(m.model));
  std::vector<math::SE3> rest;
  for (const char* b : kBodies) rest.push_back(d.oMf[m.model.frameIndex(b)]);
  std::vector<MannequinSetup> setups;
  setups.push_back(std::move(m));
  SimConfig cfg;
  cfg.target_twist = feed_forward;
  World w(std::move(setups), cfg);
  auto frameAt = [&](std::int64_t stamp_ns) {
    const double t = static_cast<double>(stamp_ns) * 1e-9, a = 2 * M_PI * t;
    mocap::Frame f;
    f.stamp_ns = stamp_ns;
    for (int i = 0; i < 6; ++i) {
      math::SE3 H = rest[i];
      if (i == 0) H.p += math::Vector3(0.03 * std::sin(a / 2), 0.03 * std::sin(a / 3), 0);
      if (i == 2) H.p += math::Vector3(0.2 * std::sin(a), 0, 0.2 * (1 - std::cos(a)));
      if (i == 3) H.p += math::Vector3(0.2 * (1 - std::cos(a)), 0, 0.2 * std::sin(a));
      f.bodies.push_back({kBodies[i], H, true});
    }
    return f;
  };
  w.addMocap(frameAt(0));
  w.anchor(0);
  std::int64_t next_frame = 0;
  double hand_err = 0, pelvis_err = 0;
  long n = 0;
  for (auto _ : state) {
    if (w.captureTimeNs() >= next_frame) {  // 120 Hz capture
      next_frame += 8'333'333;
      w.addMocap(frameAt(next_frame));
    }
    benchmark::DoNotOptimize(w.step());
    pelvis_err += w.controlFrames(0)[0].position_error;
    hand_err += w.controlFrames(0)[2].position_error;
    ++n;
  }
  state.SetLabel(std::string(w.stepper(0).kind()));
  state.counters["hand_err_mm"] = n ? 1e3 * hand_err / static_cast<double>(n) : 0.0;
  state.counters["pelvis_err_mm"] = n ? 1e3 * pelvis_err / static_cast<double>(n) : 0.0;
  state.counters["failed_steps"] = static_cast<double>(w.failedSteps());
}
}  // namespace

namespace {

using collision::SceneSpec;

collision::BodySpec staticBody(const std::string& name, const collision::Shape& shape, const math::SE3& pose) {
  collision::BodySpec b;
  b.name = name;
  b.pose = pose;
  b.shapes.push_back({shape, math::SE3::Identity()});
  return b;
}

math::SE3 at(const math::Vector3& p) {
  math::SE3 H = math::SE3::Identity();
  H.p = p;
  return H;
}

/// The floor and `spheres` static spheres (radius 15 mm) each `gap` m (after margins) from exactly one
/// segment of the standing mannequin and farther than the activation distance from every other one, so
/// that each brings one contact row (see the file comment). Candidates: a probe sphere moved around each
/// segment's centre of mass along spread directions gives the witness point and normal on the segment;
/// the sphere goes there, pushed out along the normal, and is kept when it is in range of that segment
/// only and clear of the spheres already placed.
SceneSpec ringedScene(const skeleton::Model& model, const skeleton::Data& d, bool floor, int spheres, double seg_margin) {
  SceneSpec s;
  s.name = "bench";
  s.default_mu = 0.5;
  s.friction.push_back({"skin", "probe", 0.0});
  if (floor) s.bodies.push_back(staticBody("floor", collision::Shape::plane(math::Vector3::UnitZ(), 0.0), math::SE3::Identity()));
  if (spheres <= 0) return s;
  constexpr double kActivation = 0.02, kGap = 0.001, kRadius = 0.015, kReach = 0.6;
  collision::CollisionWorld probe(collision::WorldOptions{kReach + 1.0, 1, 15.0});
  collision::MannequinOptions mo;
  mo.name = "operator";
  mo.margin = seg_margin;
  mo.self_collision = false;
  const int mi = probe.addMannequin(model, mo);
  probe.updateMannequin(mi, d);
  std::vector<int> segs;
  for (int k = 0; k < static_cast<int>(model.segments.size()); ++k)
    if (probe.segmentBody(mi, k) >= 0) segs.push_back(k);
  const int pid = probe.addBody("probe", {{collision::Shape::sphere(kRadius), math::SE3::Identity()}}, math::SE3::Identity(),
                                collision::BodyKind::kMovable);
  const int nseg = static_cast<int>(segs.size());
  constexpr int kDirections = 96;  // candidates per segment
  std::vector<math::Vector3> placed;
  collision::ContactSet set;
  for (int i = 0; i < nseg * kDirections && static_cast<int>(placed.size()) < spheres; ++i) {
    const int k = segs[static_cast<std::size_t>(i % nseg)], j = i / nseg;
    // Fibonacci directions, spread over the sphere
    const double z = 1.0 - (2.0 * j + 1.0) / kDirections, rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = j * M_PI * (3.0 - std::sqrt(5.0)) + 0.7 * k;
    const math::Vector3 dir(rho * std::cos(phi), rho * std::sin(phi), z);
    const skeleton::Segment& seg = model.segments[static_cast<std::size_t>(k)];
    const math::Vector3 c = d.oMi[static_cast<std::size_t>(seg.joint)].act(seg.com);
    const int body = probe.segmentBody(mi, k);
    probe.setActivationDistance(kReach + 1.0);
    probe.setBodyPose(pid, at(c + kReach * dir));
    probe.query(0, set);
    std::optional<math::Vector3> centre;
    for (const collision::Contact& ct : set.contacts)
      if (ct.body_a == body && ct.body_b == pid)
        centre = probe.bodyPose(body).act(ct.point_a) + (kRadius + seg_margin + kGap) * ct.normal;
    if (!centre || (floor && centre->z() < kRadius + kActivation)) continue;  // the floor's side is the floor's
    bool clear = true;
    for (const math::Vector3& p : placed) clear = clear && (p - *centre).norm() > 2 * kRadius + 0.002;
    if (!clear) continue;
    // in range of this segment only
    probe.setActivationDistance(kActivation);
    probe.setBodyPose(pid, at(*centre));
    probe.query(0, set);
    int in_range = 0;
    bool ours = false;
    for (const collision::Contact& ct : set.contacts) {
      if (ct.body_b != pid && ct.body_a != pid) continue;
      ++in_range;
      ours = ours || ct.body_a == body || ct.body_b == body;
    }
    if (in_range != 1 || !ours) continue;
    placed.push_back(*centre);
    s.bodies.push_back(staticBody("s" + std::to_string(placed.size()), collision::Shape::sphere(kRadius), at(*centre)));
    s.bodies.back().material = "probe";  // frictionless with skin: one row per contact
  }
  return s;
}

struct PhysicsRun {
  std::unique_ptr<World> world;
  std::vector<math::SE3> targets;  // per kBodies entry
};

PhysicsRun physicsWorld(const SceneSpec& scene, const char* controller, const std::vector<math::SE3>* targets,
                        const math::Vector3& gravity) {
  MannequinSetup m;
  m.name = "operator";
  m.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  for (const char* b : kBodies) m.frames.push_back({b, b});
  m.controller = control::loadControllerConfig(mannequin::bench::dataFile(controller));
  skeleton::Data d(m.model);
  skeleton::forwardKinematics(m.model, d, skeleton::standingConfiguration(m.model));
  PhysicsRun run;
  if (targets != nullptr)
    run.targets = *targets;
  else
    for (const char* b : kBodies) run.targets.push_back(d.oMf[static_cast<std::size_t>(m.model.frameIndex(b))]);
  std::vector<MannequinSetup> setups;
  setups.push_back(std::move(m));
  SimConfig cfg;
  cfg.physics.enabled = true;
  cfg.physics.scene = scene;
  cfg.physics.gravity = gravity;
  run.world = std::make_unique<World>(std::move(setups), cfg);
  return run;
}

mocap::Frame still(const std::vector<math::SE3>& poses, std::int64_t stamp_ns) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  for (std::size_t i = 0; i < poses.size(); ++i) f.bodies.push_back({kBodies[i], poses[i], true});
  return f;
}

/// Steps `run` (a still 120 Hz capture; calibrated on the first frame at the standing pose, then
/// `targets`), 100 warm-up steps, then the measured ones.
void measure(benchmark::State& state, PhysicsRun& run, const std::vector<math::SE3>& calibration) {
  World& w = *run.world;
  w.addMocap(still(calibration, 0));
  w.anchor(0);
  std::int64_t next_frame = 0;
  const auto feed = [&] {
    if (w.captureTimeNs() >= next_frame) {
      next_frame += 8'333'333;
      w.addMocap(still(run.targets, next_frame));
    }
  };
  for (int i = 0; i < 100; ++i) {
    feed();
    w.step();
  }
  double contacts = 0, active = 0, lcp = 0, pivots = 0, col = 0, cons = 0, integ = 0, max_pen = 0;
  long n = 0;
  for (auto _ : state) {
    feed();
    benchmark::DoNotOptimize(w.step());
    const StepDiagnostics& dg = w.diagnostics();
    contacts += dg.contacts;
    active += dg.active_contacts;
    lcp += dg.solver.lcp_size;
    pivots += dg.solver.pivots;
    col += dg.collision_s;
    cons += dg.constraints_s;
    integ += dg.integrate_s;
    max_pen = std::max(max_pen, dg.max_penetration_m);
    ++n;
  }
  const double inv = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
  state.counters["contacts"] = contacts * inv;
  state.counters["active"] = active * inv;
  state.counters["lcp"] = lcp * inv;
  state.counters["pivots"] = pivots * inv;
  state.counters["collision_us"] = 1e6 * col * inv;
  state.counters["constraints_us"] = 1e6 * cons * inv;
  state.counters["integrate_us"] = 1e6 * integ * inv;
  state.counters["max_pen_mm"] = 1e3 * max_pen;
  state.counters["lcp_failures"] = w.constraintSolver() ? static_cast<double>(w.constraintSolver()->failures()) : 0.0;
  state.counters["failed_steps"] = static_cast<double>(w.failedSteps());
}

constexpr double kSegmentMargin = 0.005;  // PhysicsConfig's default

void contactSweep(benchmark::State& state, int target) {
  const skeleton::Model model =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  // F: the feet's floor contacts of the standing pose (a query of the floor alone)
  int floor_contacts = 0;
  if (target > 0) {
    collision::CollisionWorld cw;
    cw.addScene(ringedScene(model, d, true, 0, kSegmentMargin));
    collision::MannequinOptions mo;
    mo.name = "operator";
    mo.margin = kSegmentMargin;
    mo.self_collision = false;
    cw.updateMannequin(cw.addMannequin(model, mo), d);
    collision::ContactSet set;
    cw.query(0, set);
    floor_contacts = static_cast<int>(set.contacts.size());
  }
  PhysicsRun run = physicsWorld(ringedScene(model, d, target > 0, std::max(0, target - floor_contacts), kSegmentMargin),
                                "configs/control/mocap.yaml", nullptr,
                                math::Vector3::Zero());  // contacts:0 has no floor to stand on
  const std::vector<math::SE3> calibration = run.targets;
  measure(state, run, calibration);
}

void handsOnTable(benchmark::State& state) {
  const skeleton::Model model =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  SceneSpec scene = ringedScene(model, d, true, 0, kSegmentMargin);
  std::vector<math::SE3> calibration, targets;
  for (const char* b : kBodies) calibration.push_back(d.oMf[static_cast<std::size_t>(model.frameIndex(b))]);
  targets = calibration;
  for (const char* hand : {"hand_l", "hand_r"}) {
    // the lowest point of the hand's capsule: the top of its table (the margin shells touch)
    const skeleton::Segment& seg = model.segments[static_cast<std::size_t>(model.findSegment(hand))];
    collision::CollisionWorld cw(collision::WorldOptions{10.0, 1, 15.0});
    cw.addScene(ringedScene(model, d, true, 0, 0.0));
    collision::MannequinOptions mo;
    mo.name = "operator";
    mo.self_collision = false;
    const int mi = cw.addMannequin(model, mo);
    cw.updateMannequin(mi, d);
    collision::ContactSet set;
    cw.query(0, set);
    const int body = cw.segmentBody(mi, model.findSegment(hand));
    double bottom = std::numeric_limits<double>::infinity();  // height of the hand's lowest point above the floor
    for (const collision::Contact& c : set.contacts)
      if (c.body_a == body || c.body_b == body) bottom = std::min(bottom, c.distance);
    const math::Vector3 com = d.oMi[static_cast<std::size_t>(seg.joint)].act(seg.com);
    const double top = bottom - kSegmentMargin;
    scene.bodies.push_back(staticBody(std::string("table_") + hand, collision::Shape::box(math::Vector3(0.3, 0.3, 0.04)),
                                      at(math::Vector3(com.x(), com.y(), top - 0.02))));
    for (std::size_t i = 0; i < std::size(kBodies); ++i)
      if (std::string(kBodies[i]) == hand) targets[i].p.z() -= 0.01;  // pressing on the table
  }
  PhysicsRun run = physicsWorld(scene, "configs/control/default.yaml", &targets, math::Vector3(0, 0, -9.81));
  measure(state, run, calibration);
}

}  // namespace

static void BM_PhysicsStep(benchmark::State& state, int contacts) { contactSweep(state, contacts); }
static void BM_PhysicsStandingHandsOnTable(benchmark::State& state) { handsOnTable(state); }

static void registerContactSweep() {
  for (int n = 0; n <= 300; n += (n < 280 ? 10 : 20)) {
    benchmark::RegisterBenchmark(("BM_PhysicsStep/contacts:" + std::to_string(n)).c_str(),
                                 [n](benchmark::State& st) { BM_PhysicsStep(st, n); })
        ->Unit(benchmark::kMicrosecond);
  }
}
static const int kRegistered = (registerContactSweep(), 0);
BENCHMARK(BM_PhysicsStandingHandsOnTable)->Name("BM_PhysicsStep/standing_hands_on_table")->Unit(benchmark::kMicrosecond);

static void BM_WorldStep(benchmark::State& state, bool controller, bool feed_forward) {
  worldStep(state, controller, feed_forward);
}
BENCHMARK_CAPTURE(BM_WorldStep, controller, true, true)->Unit(benchmark::kMicrosecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_WorldStep, controller_no_target_twist, true, false)->Unit(benchmark::kMicrosecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_WorldStep, kinematic, false, false)->Unit(benchmark::kMicrosecond)->MinTime(2.0);

MANNEQUIN_BENCHMARK_MAIN("bench-step", "configs/mannequins/male_50th.yaml", "configs/control/mocap.yaml",
                         "configs/control/default.yaml")
