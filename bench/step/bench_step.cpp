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
//   BM_PhysicsStep/standing_hands_on_table   configs/control/default.yaml, gravity on (PhysicsConfig), standing
//       on the floor with both hands resting palm down on a table in front (see handsOnTable: the set-up
//       is checked and the case fails with an error when it is not what it claims).
// Counters: contacts (mean contact rows per step, measured), active (λ > 0), lcp (LCP size), pivots,
// warm (share of the LCP solves the warm start answered, 0 pivots),
// per-stage µs (collision, constraints = rows + assemble + lcp, integrate), max_pen_mm, lcp_failures, failed_steps.
// Kinetics of the offline runs, per sample (see kineticsCase): BM_Kinetics/solve and BM_Kinetics/sample.
// With libmujoco-dev: BM_MujocoStep/contacts:N and BM_MujocoTrackingStep/contacts:N, the same scene in MuJoCo
// at our settled pose (equal contact counts), bare or following the same six targets (see mujocoSweep).
#include <benchmark/benchmark.h>

#include <chrono>
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
#include "mannequin/kinetics/kinetics.hpp"
#include "mannequin/sim/kinetics_recorder.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/mjcf.hpp"

#ifdef MANNEQUIN_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#endif

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

/// Drives `run` with a still 120 Hz capture: calibrated on the first frame (`calibration`), then
/// `run.targets` every 8 or 9 steps.
struct Driver {
  PhysicsRun& run;
  std::int64_t next_frame = 0;
  Driver(PhysicsRun& r, const std::vector<math::SE3>& calibration) : run(r) {
    run.world->addMocap(still(calibration, 0));
    run.world->anchor(0);
  }
  bool step() {
    World& w = *run.world;
    if (w.captureTimeNs() >= next_frame) {
      next_frame += 8'333'333;
      w.addMocap(still(run.targets, next_frame));
    }
    return w.step();
  }
};

/// Steps `run` (see Driver) `warmup` times (unless `driver` has already warmed it up), then the
/// measured ones.
void measure(benchmark::State& state, Driver& driver, int warmup = 100) {
  World& w = *driver.run.world;
  for (int i = 0; i < warmup; ++i) driver.step();
  double contacts = 0, active = 0, lcp = 0, pivots = 0, col = 0, cons = 0, integ = 0, max_pen = 0;
  double produce = 0, assemble = 0, solve = 0, solves = 0, warm = 0;
  long n = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(driver.step());
    const StepDiagnostics& dg = w.diagnostics();
    contacts += dg.contacts;
    active += dg.active_contacts;
    lcp += dg.solver.lcp_size;
    pivots += dg.solver.pivots;
    col += dg.collision_s;
    cons += dg.constraints_s;
    integ += dg.integrate_s;
    produce += dg.solver.produce_s;
    assemble += dg.solver.assemble_s;
    solve += dg.solver.solve_s;
    solves += dg.solver.lcp_solves;
    warm += dg.solver.warm;
    max_pen = std::max(max_pen, dg.max_penetration_m);
    ++n;
  }
  const double inv = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
  state.counters["contacts"] = contacts * inv;
  state.counters["active"] = active * inv;
  state.counters["lcp"] = lcp * inv;
  state.counters["pivots"] = pivots * inv;
  state.counters["warm"] = solves > 0 ? warm / solves : 0.0;  // share of LCP solves the warm start answered
  state.counters["collision_us"] = 1e6 * col * inv;
  state.counters["constraints_us"] = 1e6 * cons * inv;
  state.counters["rows_us"] = 1e6 * produce * inv;
  state.counters["assemble_us"] = 1e6 * assemble * inv;
  state.counters["lcp_us"] = 1e6 * solve * inv;
  state.counters["integrate_us"] = 1e6 * integ * inv;
  state.counters["max_pen_mm"] = 1e3 * max_pen;
  state.counters["lcp_failures"] = w.constraintSolver() ? static_cast<double>(w.constraintSolver()->failures()) : 0.0;
  state.counters["failed_steps"] = static_cast<double>(w.failedSteps());
}

void measure(benchmark::State& state, PhysicsRun& run, const std::vector<math::SE3>& calibration) {
  Driver driver(run, calibration);
  measure(state, driver);
}

constexpr double kSegmentMargin = 0.005;  // PhysicsConfig's default

/// The contact sweep's set-up for `target` contact rows (see the file comment): the standing
/// male_50th, its floor contacts F and the scene (floor and target − F spheres).
struct SweepSetup {
  skeleton::Model model;
  skeleton::VectorX q;
  SceneSpec scene;
  int floor_contacts = 0;
};

SweepSetup sweepSetup(int target) {
  SweepSetup s;
  s.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  const skeleton::Model& model = s.model;
  s.q = skeleton::standingConfiguration(model);
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, s.q);
  // F: the feet's floor contacts of the standing pose (a query of the floor alone)
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
    s.floor_contacts = static_cast<int>(set.contacts.size());
  }
  s.scene = ringedScene(model, d, target > 0, std::max(0, target - s.floor_contacts), kSegmentMargin);
  return s;
}

PhysicsRun sweepWorld(const SweepSetup& s) {
  return physicsWorld(s.scene, "configs/control/mocap.yaml", nullptr,
                      math::Vector3::Zero());  // contacts:0 has no floor to stand on
}

void contactSweep(benchmark::State& state, int target) {
  PhysicsRun run = sweepWorld(sweepSetup(target));
  const std::vector<math::SE3> calibration = run.targets;
  measure(state, run, calibration);
}

/// Height of the lowest point of `segment`'s real geometry (no margin) above the floor z = 0, at `q`.
double segmentBottom(const skeleton::Model& model, const skeleton::VectorX& q, const char* segment) {
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, q);
  collision::CollisionWorld cw(collision::WorldOptions{10.0, 1, 15.0});
  cw.addScene(ringedScene(model, d, true, 0, 0.0));
  collision::MannequinOptions mo;
  mo.name = "operator";
  mo.self_collision = false;
  const int mi = cw.addMannequin(model, mo);
  cw.updateMannequin(mi, d);
  collision::ContactSet set;
  cw.query(0, set);
  const int body = cw.segmentBody(mi, model.findSegment(segment));
  double bottom = std::numeric_limits<double>::infinity();
  for (const collision::Contact& c : set.contacts)
    if (c.body_a == body || c.body_b == body) bottom = std::min(bottom, c.distance);
  return bottom;
}

/// The mannequin standing on the floor under gravity (configs/control/default.yaml), forearms forward,
/// both hands resting palm down on one table in front of it and pressing on it (hand targets 1 cm
/// below the top). Set-up: a first World without the table settles the pose (hands forward, 1 s);
/// the table's top goes at the lower of the two hands' real geometry; the measured World is calibrated
/// on the settled pose and warmed up 1 s before timing. Checked (SkipWithError otherwise) after the
/// warm-up and after the run: each hand carries a normal force from the table, only hand and forearm
/// segments touch the table, no real-geometry penetration beyond the segment margin, a foot on the
/// floor with its sole within the margin of it.
void handsOnTable(benchmark::State& state) {
  const skeleton::Model model =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  std::vector<math::SE3> standing, forward;
  for (const char* b : kBodies) standing.push_back(d.oMf[static_cast<std::size_t>(model.frameIndex(b))]);
  // forearms forward: wrists 0.32 m forward, 0.2 m up, 4 cm inwards; palms turned down by 0.8π about
  // the forearm (pronation: +x for the left hand, −x for the right), fingers forward
  forward = standing;
  for (std::size_t i : {std::size_t{2}, std::size_t{3}}) {
    const bool left = i == 2;  // hand_l is on +y
    forward[i].p += math::Vector3(0.32, left ? -0.04 : 0.04, 0.20);
    forward[i].R = math::expSO3(math::Vector3((left ? 0.8 : -0.8) * M_PI, 0, 0)) *
                   math::expSO3(math::Vector3(0, -M_PI / 2, 0)) * standing[i].R;
  }
  const math::Vector3 gravity(0, 0, -9.81);
  // 1. the pose without the table
  SceneSpec floor_only = ringedScene(model, d, true, 0, kSegmentMargin);
  PhysicsRun pre = physicsWorld(floor_only, "configs/control/default.yaml", &forward, gravity);
  {
    Driver drv(pre, standing);
    for (int i = 0; i < 1000; ++i) drv.step();
  }
  std::vector<math::SE3> settled;
  for (const DrivenFrame& f : pre.world->controlFrames(0)) settled.push_back(f.actual);
  const skeleton::VectorX q_settled = pre.world->q(0);
  const double top = std::min(segmentBottom(model, q_settled, "hand_l"), segmentBottom(model, q_settled, "hand_r"));
  const double wrist_x = std::min(settled[2].p.x(), settled[3].p.x());
  // 2. the table: 0.9 m wide, 0.5 m deep from 2 cm in front of the wrists (the palms rest on it, the
  // forearms clear its edge), 4 cm thick
  SceneSpec scene = floor_only;
  scene.bodies.push_back(staticBody("table", collision::Shape::box(math::Vector3(0.5, 0.9, 0.04)),
                                    at(math::Vector3(wrist_x + 0.27, 0.5 * (settled[2].p.y() + settled[3].p.y()), top - 0.02))));
  std::vector<math::SE3> pressing = settled;
  pressing[2].p.z() -= 0.01;
  pressing[3].p.z() -= 0.01;
  // the hands come over the table first (from hanging at the sides), then press on it
  std::vector<math::SE3> above = settled;
  above[2].p.z() += 0.12;
  above[3].p.z() += 0.12;
  PhysicsRun run = physicsWorld(scene, "configs/control/default.yaml", &above, gravity);
  Driver driver(run, standing);
  World& w = *run.world;
  const collision::CollisionWorld& cw = *w.collisionWorld();
  const int table = cw.findBody("scene/table");
  if (table < 0) {
    state.SkipWithError("no body 'scene/table' in the World's collision world");
    return;
  }
  // the set-up's claims over a window of steps
  struct Check {
    double force_l = 0, force_r = 0, max_pen = 0, worst_sole = 0;
    int feet_on_floor = 0, steps = 0;
    std::string other;  // a segment other than hands/forearms pressing on the table
  };
  const auto observe = [&](Check& c) {
    ++c.steps;
    const StepDiagnostics& dg = w.diagnostics();
    c.max_pen = std::max(c.max_pen, dg.max_penetration_m);
    const MannequinDiagnostics& md = w.mannequinDiagnostics(0);
    if (md.foot_contact) ++c.feet_on_floor;
    c.worst_sole = std::max(c.worst_sole, std::abs(md.sole_height_m));
    for (const ContactReport& r : w.contacts()) {
      if (r.body_a != table && r.body_b != table) continue;
      const std::string& other = cw.bodyName(r.body_a == table ? r.body_b : r.body_a);
      if (r.normal_force <= 0) continue;
      if (other.find("hand_l") != std::string::npos) c.force_l += r.normal_force;
      else if (other.find("hand_r") != std::string::npos) c.force_r += r.normal_force;
      else if (other.find("forearm") == std::string::npos) c.other = other;
    }
  };
  const auto verdict = [&](const Check& c, const char* when) -> std::string {
    const double n = std::max(1, c.steps);
    std::string e;
    if (c.force_l / n < 1.0 || c.force_r / n < 1.0)
      e = "a hand does not rest on the table (mean normal force L " + std::to_string(c.force_l / n) + " N, R " +
          std::to_string(c.force_r / n) + " N)";
    else if (!c.other.empty())
      e = "'" + c.other + "' presses on the table";
    else if (c.max_pen > kSegmentMargin)
      e = "real-geometry penetration " + std::to_string(1e3 * c.max_pen) + " mm > the margin";
    else if (c.feet_on_floor < c.steps || c.worst_sole > kSegmentMargin + 0.002)
      e = "feet not on the floor (" + std::to_string(c.feet_on_floor) + "/" + std::to_string(c.steps) +
          " steps, worst |sole height| " + std::to_string(1e3 * c.worst_sole) + " mm)";
    return e.empty() ? e : std::string(when) + ": " + e;
  };
  for (int i = 0; i < 500; ++i) driver.step();
  run.targets = pressing;
  Check warm;
  for (int i = 0; i < 1000; ++i) {
    driver.step();
    if (i >= 500) observe(warm);
  }
  if (const std::string e = verdict(warm, "after warm-up"); !e.empty()) {
    state.SkipWithError(e.c_str());
    return;
  }
  measure(state, driver, 0);
  Check after;
  for (int i = 0; i < 100; ++i) {
    driver.step();
    observe(after);
  }
  if (const std::string e = verdict(after, "after the run"); !e.empty()) {
    state.SkipWithError(e.c_str());
    return;
  }
  state.counters["hand_l_N"] = warm.force_l / warm.steps;
  state.counters["hand_r_N"] = warm.force_r / warm.steps;
  state.counters["table_top_m"] = top;
}

}  // namespace

#ifdef MANNEQUIN_HAVE_MUJOCO
namespace {

/// The contact sweep's scene in MuJoCo: the mannequin exported by skeleton::toMjcf (same joints, masses,
/// capsules, box feet; gravity 0 as the sweep), the floor and the same spheres as static geoms. Contacts
/// in the same range as ours: our pairs become rows within the activation distance (2 cm) of the
/// segments' margin shells (5 mm; the scene has none), so MuJoCo's geom margin is 2.5 cm on the real
/// geometry, all its contacts in its solver (no gap). Spheres frictionless (condim 1, priority 1 so that
/// their condim wins over the mannequin's 3) as ours; the floor with friction 0.5 (pyramidal cones: 4 rows
/// per contact, MuJoCo's default). MuJoCo's defaults otherwise: Euler, Newton solver.
///
/// The same pose: our World steps first (warm-up, 300 steps: the contacts push the standing mannequin a
/// little, some of the scene's contacts leave the range and others enter), then every MuJoCo step starts
/// from our configuration at that moment (mjcfQpos; qvel 0: a copy of 51 + 43 doubles, timed with the
/// step). MuJoCo's soft contacts push from the margin on (ours: λ = 0 until touching) and, without
/// tracking, nothing holds its mannequin, so it would drift out of range: hence the reset. Both engines
/// then count the same contacts (counters `contacts` and `ours_contacts`): the goal compares at equal
/// contact count.
///
/// `tracking` (BM_MujocoTrackingStep): MuJoCo does our step's job too — the six frames (kBodies) follow
/// six mocap targets, MuJoCo's way: a mocap body per target, welded (relpose identity) to the body of the
/// joint carrying the frame, each target where its body is in the reset state (the welds start every step
/// with zero violation, checked: the case fails otherwise). 36 equality rows for our 36 task rows.
///
/// Times mj_step; then times our World (continuing) over as many steps (at least 200) with a steady clock
/// and reports: contacts (MuJoCo's d->ncon, mean), efc (its constraint rows), ours_contacts (our contact
/// rows, mean), ours_us, mujoco_us and ratio = ours_us / mujoco_us.
void mujocoSweep(benchmark::State& state, int target, bool tracking) {
  // MuJoCo prints warnings on stdout (and appends them to MUJOCO_LOG.TXT): stderr keeps the JSON valid
  mju_user_warning = [](const char* msg) { std::fprintf(stderr, "bench-step: MuJoCo warning: %s\n", msg); };
  const SweepSetup setup = sweepSetup(target);
  // ours first: settled, its configuration is MuJoCo's state
  PhysicsRun run = sweepWorld(setup);
  const std::vector<math::SE3> calibration = run.targets;
  Driver driver(run, calibration);
  for (int i = 0; i < 300; ++i) driver.step();
  const skeleton::VectorX q_settled = run.world->q(0);
  // our pairs become rows within the activation distance of the segments' margin shells (the scene
  // has no margin); MuJoCo's geom margin is on the real geometry
  const PhysicsConfig physics_defaults;
  const double mj_margin = physics_defaults.activation_distance + physics_defaults.segment_margin;
  std::string spheres;
  for (const collision::BodySpec& b : setup.scene.bodies) {
    if (b.shapes.empty() || b.shapes[0].shape.type != collision::ShapeType::kSphere) continue;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "    <geom name=\"%s\" type=\"sphere\" size=\"%.9g\" pos=\"%.12g %.12g %.12g\" contype=\"1\" "
                  "conaffinity=\"1\" condim=\"1\" priority=\"1\" margin=\"%.9g\"/>\n",
                  b.name.c_str(), b.shapes[0].shape.radius, b.pose.p.x(), b.pose.p.y(), b.pose.p.z(), mj_margin);
    spheres += buf;
  }
  skeleton::MjcfOptions opt;
  opt.gravity = math::Vector3::Zero();
  opt.floor = false;  // written below with the activation margin
  opt.nconmax = 1000;
  opt.njmax = 4000;
  if (target > 0)
    spheres += "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" contype=\"1\" conaffinity=\"1\" condim=\"3\" "
               "friction=\"0.5 0.005 0.0001\" margin=\"" + std::to_string(mj_margin) + "\"/>\n";
  // tracking: one mocap body per driven frame (kBodies), welded to the body of the joint carrying it
  std::vector<std::string> weld_bodies;
  std::string equality;
  if (tracking) {
    equality = "  <equality>\n";
    for (const char* b : kBodies) {
      const skeleton::Model& model = setup.model;
      const int j = model.frames[static_cast<std::size_t>(model.frameIndex(b))].joint;
      weld_bodies.push_back(model.joints[static_cast<std::size_t>(j)].name);
      spheres += std::string("    <body name=\"target_") + b + "\" mocap=\"true\"/>\n";
      equality += "    <weld body1=\"" + weld_bodies.back() + "\" body2=\"target_" + b + "\" relpose=\"0 0 0 1 0 0 0\"/>\n";
    }
    equality += "  </equality>\n";
  }
  opt.extra_worldbody = spheres;
  std::string xml = skeleton::toMjcf(setup.model, opt);
  if (tracking) xml.insert(xml.rfind("</mujoco>"), equality);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bench_step_mujoco_" + std::to_string(::getpid()) + "_" + std::to_string(target) + ".xml"))
                               .string();
  { std::ofstream(path) << xml; }
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  std::filesystem::remove(path);
  if (m == nullptr) {
    state.SkipWithError((std::string("MuJoCo refuses the exported model: ") + err).c_str());
    return;
  }
  mjData* d = mj_makeData(m);
  const std::vector<double> qpos = skeleton::mjcfQpos(setup.model, q_settled);
  for (int i = 0; i < m->nq; ++i) d->qpos[i] = qpos[static_cast<std::size_t>(i)];
  const auto reset = [&] {
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = qpos[static_cast<std::size_t>(i)];
    for (int i = 0; i < m->nv; ++i) d->qvel[i] = 0.0;
  };
  if (tracking) {  // each target where its body is in the state every step starts from
    reset();
    mj_forward(m, d);
    for (std::size_t k = 0; k < weld_bodies.size(); ++k) {
      const int b = mj_name2id(m, mjOBJ_BODY, weld_bodies[k].c_str());
      const int t = mj_name2id(m, mjOBJ_BODY, (std::string("target_") + kBodies[k]).c_str());
      if (b < 0 || t < 0 || m->body_mocapid[t] < 0) {
        state.SkipWithError(("MuJoCo model: no body " + weld_bodies[k] + " or target_" + kBodies[k]).c_str());
        mj_deleteData(d);
        mj_deleteModel(m);
        return;
      }
      const int mc = m->body_mocapid[t];
      for (int c = 0; c < 3; ++c) d->mocap_pos[3 * mc + c] = d->xpos[3 * b + c];
      for (int c = 0; c < 4; ++c) d->mocap_quat[4 * mc + c] = d->xquat[4 * b + c];
    }
    mj_forward(m, d);  // the welds' violation in the reset state: none
    double violation = 0;
    for (int i = 0; i < d->nefc; ++i)
      if (d->efc_type[i] == mjCNSTR_EQUALITY) violation = std::max(violation, std::abs(d->efc_pos[i]));
    if (violation > 1e-9) {
      state.SkipWithError(("MuJoCo's welds start violated by " + std::to_string(violation) + " (expected 0)").c_str());
      mj_deleteData(d);
      mj_deleteModel(m);
      return;
    }
  }
  for (int i = 0; i < 100; ++i) {  // warm-up, as ours
    reset();
    mj_step(m, d);
  }
  double ncon = 0, nefc = 0;
  long n = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    reset();
    mj_step(m, d);
    ncon += d->ncon;
    nefc += d->nefc;
    ++n;
  }
  const double mujoco_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  mj_deleteData(d);
  mj_deleteModel(m);
  // ours, continuing from the settled state, as many steps (at least 200)
  const long ours_n = std::max(200L, n);
  double ours_contacts = 0;
  const auto t1 = std::chrono::steady_clock::now();
  for (long i = 0; i < ours_n; ++i) {
    benchmark::DoNotOptimize(driver.step());
    ours_contacts += run.world->diagnostics().contacts;
  }
  const double ours_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const double inv = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
  state.counters["contacts"] = ncon * inv;
  state.counters["efc"] = nefc * inv;
  state.counters["ours_contacts"] = ours_contacts / static_cast<double>(ours_n);
  state.counters["mujoco_us"] = 1e6 * mujoco_s * inv;
  state.counters["ours_us"] = 1e6 * ours_s / static_cast<double>(ours_n);
  state.counters["ratio"] = mujoco_s > 0 ? (ours_s / static_cast<double>(ours_n)) / (mujoco_s * inv) : 0.0;
}

}  // namespace

static void registerMujocoSweep() {
  for (const bool tracking : {false, true})
    for (int n = 0; n <= 300; n += (n < 280 ? 10 : 20)) {
      benchmark::RegisterBenchmark(
          ((tracking ? "BM_MujocoTrackingStep/contacts:" : "BM_MujocoStep/contacts:") + std::to_string(n)).c_str(),
          [n, tracking](benchmark::State& st) { mujocoSweep(st, n, tracking); })
          ->Unit(benchmark::kMicrosecond);
    }
}
static const int kMujocoRegistered = (registerMujocoSweep(), 0);
#endif

namespace {
/// The whole-body kinetics of the offline runs (sim::KineticsRecorder, libs/kinetics) on the mannequin
/// standing on the floor (mocap.yaml, gravity on, targets at the standing pose), settled 500 steps:
///   solve    World::kineticsInputs + KineticsSolver::solve of its current posture at rest (v = a = 0)
///   sample   KineticsRecorder::sample (what the offline run adds after every step)
/// Counters: contacts, grf_over_weight (the solved contact force's vertical part over the weight: at rest
/// it is 1 when the contacts carry the body), residual_n, and step_us / ratio (a World step of the same
/// set-up, timed in the same run, and the case's time over it).
void kineticsCase(benchmark::State& state, bool recorder) {
  const skeleton::Model model =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  const math::Vector3 gravity(0, 0, -9.81);
  PhysicsRun run = physicsWorld(ringedScene(model, d, true, 0, kSegmentMargin), "configs/control/mocap.yaml", nullptr, gravity);
  Driver driver(run, run.targets);
  for (int i = 0; i < 500; ++i) driver.step();
  World& w = *run.world;
  constexpr int kSteps = 200;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kSteps; ++i) driver.step();
  const double step_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / kSteps;
  if (!w.calibrated(0) || w.failedSteps() > 0) {
    state.SkipWithError("the standing mannequin is not calibrated or a step failed");
    return;
  }
  std::vector<kinetics::ContactPoint> contacts;
  std::vector<kinetics::Load> loads;
  long n = 0;
  const auto t1 = std::chrono::steady_clock::now();
  if (recorder) {
    KineticsRecorder rec(w);
    for (auto _ : state) {
      rec.sample(w);
      ++n;
    }
    w.kineticsInputs(0, contacts, loads);
  } else {
    kinetics::KineticsOptions options;
    options.gravity = gravity;
    kinetics::KineticsSolver solver(w.model(0), options);
    const math::VectorX zero = math::VectorX::Zero(model.nv);
    kinetics::KineticsFrame f;
    for (auto _ : state) {
      w.kineticsInputs(0, contacts, loads);
      f = solver.solve(w.q(0), zero, zero, contacts, loads);
      benchmark::DoNotOptimize(f.contact_force);
      ++n;
    }
    const double weight = model.totalMass() * -gravity.z();
    state.counters["grf_over_weight"] = f.contact_force.z() / weight;
    state.counters["residual_n"] = f.residual_force.norm();
  }
  const double case_s = n > 0 ? std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count() / static_cast<double>(n) : 0.0;
  state.counters["contacts"] = static_cast<double>(contacts.size());
  state.counters["step_us"] = 1e6 * step_s;
  state.counters["ratio"] = step_s > 0 ? case_s / step_s : 0.0;
}
}  // namespace

static void BM_Kinetics(benchmark::State& state, bool recorder) { kineticsCase(state, recorder); }
BENCHMARK_CAPTURE(BM_Kinetics, solve, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Kinetics, sample, true)->Unit(benchmark::kMicrosecond);

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
