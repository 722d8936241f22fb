// bench-collision: CollisionWorld::query per step in (a) one mannequin on a floor, (b) two mannequins
// around a table, (c) one seated mannequin in the 14k-triangle cockpit, (d) a stress case with
// ~280 contacts; plus raw FCL references (broadphase vs a box floor, per-capsule distance to
// the panel mesh: the trap). Runs from any directory (configs/ and data/ found by core::findData).
#include <benchmark/benchmark.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "bench_main.hpp"
#include "mannequin/collision/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin;
using namespace mannequin::collision;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string path(const std::string& rel) { return mannequin::bench::dataFile(rel); }

const skeleton::Model& model() {
  static const skeleton::Model m =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(path("configs/mannequins/male_50th.yaml")));
  return m;
}

void set(math::VectorX& q, const char* coord, double v) {
  const auto names = model().coordinateNames();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == coord) {
      q[static_cast<Eigen::Index>(i)] = v;
      return;
    }
  std::abort();
}

/// A pose and the same pose slightly moved (the benchmark alternates them: the trees are refitted).
struct Motion {
  skeleton::Data d0, d1;
  explicit Motion(const math::VectorX& q) : d0(model()), d1(model()) {
    skeleton::forwardKinematics(model(), d0, q);
    math::VectorX q1 = q;
    for (Eigen::Index k = 6; k < q1.size(); ++k) q1[k] += 0.01 * std::sin(3.0 * static_cast<double>(k));
    q1[0] += 0.002;
    skeleton::forwardKinematics(model(), d1, q1);
  }
  const skeleton::Data& at(std::int64_t step) const { return step % 2 ? d1 : d0; }
};

math::VectorX armsForward(math::VectorX q, double flexion, double elbow) {
  set(q, "shoulder_l.y", -flexion);
  set(q, "shoulder_r.y", -flexion);
  set(q, "elbow_l", elbow);
  set(q, "elbow_r", elbow);
  return q;
}

void runQueries(benchmark::State& state, CollisionWorld& w, const std::vector<std::pair<int, const Motion*>>& people) {
  ContactSet cs;
  cs.contacts.reserve(1024);
  std::int64_t step = 0;
  std::size_t contacts = 0;
  int tris = 0, pairs = 0;
  for (auto _ : state) {
    for (const auto& [id, motion] : people) w.updateMannequin(id, motion->at(step));
    w.query(static_cast<std::uint64_t>(step), cs);
    benchmark::DoNotOptimize(cs.contacts.data());
    contacts = cs.contacts.size();
    tris = cs.stats.triangles_tested;
    pairs = cs.stats.broadphase_pairs;
    ++step;
  }
  if (std::getenv("MANNEQUIN_BENCH_VERBOSE") != nullptr)  // the contacts of the last step
    for (const auto& c : cs.contacts)
      std::fprintf(stderr, "  %-22s %-22s d=% .4f feature=%d\n", w.bodyName(c.body_a).c_str(),
                   w.bodyName(c.body_b).c_str(), c.distance, c.feature);
  state.counters["contacts"] = static_cast<double>(contacts);
  state.counters["broadphase_pairs"] = pairs;
  state.counters["triangles_tested"] = tris;
}

// (a) one mannequin standing on the floor
void BM_QueryA_MannequinOnFloor(benchmark::State& state) {
  CollisionWorld w;
  w.addScene(loadScene(path("configs/scenes/floor.yaml")));
  const int m = w.addMannequin(model());
  Motion motion(skeleton::standingConfiguration(model()));
  runQueries(state, w, {{m, &motion}});
}
BENCHMARK(BM_QueryA_MannequinOnFloor);

// (b) two mannequins on either side of the table, hands forward over it
void BM_QueryB_TwoMannequinsAroundTable(benchmark::State& state) {
  CollisionWorld w;
  w.addScene(loadScene(path("configs/scenes/table.yaml")));
  const int a = w.addMannequin(model());
  const int b = w.addMannequin(model());
  math::VectorX qa = armsForward(skeleton::standingConfiguration(model()), 0.9, 0.5);
  qa[0] = 0.0;
  math::VectorX qb = qa;
  qb[0] = 1.6;
  qb[5] = kPi;
  Motion ma(qa), mb(qb);
  runQueries(state, w, {{a, &ma}, {b, &mb}});
}
BENCHMARK(BM_QueryB_TwoMannequinsAroundTable);

// (c) one mannequin seated in the cockpit, hands on the panel
math::VectorX seated() {
  math::VectorX q = skeleton::standingConfiguration(model());
  set(q, "hip_l.y", -kPi / 2);
  set(q, "hip_r.y", -kPi / 2);
  set(q, "knee_l", kPi / 2);
  set(q, "knee_r", kPi / 2);
  q = armsForward(q, 1.2, 0.5);
  // thighs on the seat pan (top at 0.46 m), palms at the panel's front
  skeleton::Data d(model());
  skeleton::forwardKinematics(model(), d, q);
  const auto& seg = model().segments[model().segmentIndex("thigh_l")];
  const double thigh_bottom = d.oMi[seg.joint].p.z() - seg.capsule.radius;
  q[2] += 0.462 - thigh_bottom;
  return q;
}

// slides the seated mannequin along x until its hands are 5 mm from the panel
math::VectorX seatedInCockpit(CollisionWorld& w, int m) {
  math::VectorX q = seated();
  skeleton::Data d(model());
  const int panel = w.findBody("scene/panel");
  const double saved = w.activationDistance();
  w.setActivationDistance(0.5);
  ContactSet cs;
  for (int it = 0; it < 6; ++it) {
    skeleton::forwardKinematics(model(), d, q);
    w.updateMannequin(m, d);
    w.query(0, cs);
    double dmin = 1.0;
    for (const auto& c : cs.contacts)
      if (c.body_a == panel && w.bodyName(c.body_b).find("hand") != std::string::npos) dmin = std::min(dmin, c.distance);
    q[0] += dmin - 0.005;
  }
  w.setActivationDistance(saved);
  return q;
}

// the pose of (c), for the raw-FCL references
const math::VectorX& cockpitPose() {
  static const math::VectorX q = [] {
    CollisionWorld w;
    w.addScene(loadScene(path("configs/scenes/cockpit.yaml")));
    return seatedInCockpit(w, w.addMannequin(model()));
  }();
  return q;
}

void BM_QueryC_SeatedInCockpit(benchmark::State& state) {
  CollisionWorld w;
  w.addScene(loadScene(path("configs/scenes/cockpit.yaml")));
  const int m = w.addMannequin(model());
  Motion motion(seatedInCockpit(w, m));
  runQueries(state, w, {{m, &motion}});
}
BENCHMARK(BM_QueryC_SeatedInCockpit);

// (d) stress: a mannequin lying on the floor and 60 boxes resting on the table (~280 contacts)
void BM_QueryD_Stress280(benchmark::State& state) {
  CollisionWorld w;
  w.addScene(loadScene(path("configs/scenes/table.yaml")));
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 6; ++j)
      w.addBody("box" + std::to_string(i * 6 + j), {{Shape::box({0.08, 0.08, 0.08}), SE3()}},
                SE3(math::Matrix3::Identity(), math::Vector3(0.8 - 0.54 + 0.12 * i, -0.325 + 0.13 * j, 0.75 + 0.04 + 0.003)),
                BodyKind::kMovable);
  const int m = w.addMannequin(model());
  math::VectorX q = skeleton::standingConfiguration(model());
  q[0] = -0.5;
  q[1] = 1.5;
  q[4] = -kPi / 2;  // lying on the back, head towards −x
  // lower it until its lowest point touches the floor
  skeleton::Data d(model());
  skeleton::forwardKinematics(model(), d, q);
  double low = 1e9;
  for (const auto& s : model().segments) {
    const auto& H = d.oMi[s.joint];
    low = std::min({low, H.act(s.capsule.a).z() - s.capsule.radius, H.act(s.capsule.b).z() - s.capsule.radius});
  }
  q[2] -= low - 0.002;
  Motion motion(q);
  runQueries(state, w, {{m, &motion}});
}
BENCHMARK(BM_QueryD_Stress280);

// ---- raw FCL references ---------------------------------------------------------------------

std::vector<std::shared_ptr<fcl::CollisionObjectd>> capsuleObjects(const skeleton::Data& d) {
  std::vector<std::shared_ptr<fcl::CollisionObjectd>> out;
  for (const auto& s : model().segments) {
    const auto& c = s.capsule;
    const math::Vector3 dir = c.b - c.a;
    const double len = dir.norm();
    math::Matrix3 R = math::Matrix3::Identity();
    if (len > 1e-9) R = Eigen::Quaterniond::FromTwoVectors(math::Vector3::UnitZ(), dir / len).toRotationMatrix();
    const auto& H = d.oMi[s.joint];
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = H.R * R;
    tf.translation() = H.act(0.5 * (c.a + c.b));
    out.push_back(std::make_shared<fcl::CollisionObjectd>(std::make_shared<fcl::Capsuled>(c.radius, len), tf));
  }
  return out;
}

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> panelBvh() {
  const TriangleMesh mesh = loadMesh(path("data/meshes/cockpit_panel.obj"));
  auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Triangle> tris;
  for (const auto& t : mesh.triangles) tris.emplace_back(t[0], t[1], t[2]);
  bvh->beginModel();
  bvh->addSubModel(mesh.vertices, tris);
  bvh->endModel();
  return bvh;
}

fcl::Transform3d panelPose() {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation() = math::Vector3(0.05, 0, 0.75);
  return tf;
}

void BM_RawFcl_BroadphaseCollideVsBoxFloor(benchmark::State& state) {
  skeleton::Data d(model());
  skeleton::forwardKinematics(model(), d, skeleton::standingConfiguration(model()));
  auto caps = capsuleObjects(d);
  fcl::DynamicAABBTreeCollisionManagerd mgr;
  for (auto& c : caps) mgr.registerObject(c.get());
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation().z() = -0.05;
  fcl::CollisionObjectd floor(std::make_shared<fcl::Boxd>(10, 10, 0.1), tf);
  mgr.setup();
  struct Data {
    int n = 0;
  } data;
  auto cb = [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* p) {
    fcl::CollisionRequestd req;
    fcl::CollisionResultd res;
    static_cast<Data*>(p)->n += static_cast<int>(fcl::collide(a, b, req, res));
    return false;
  };
  for (auto _ : state) {
    data.n = 0;
    for (auto& c : caps) c->computeAABB();
    mgr.update();
    mgr.collide(&floor, &data, cb);
    benchmark::DoNotOptimize(data.n);
  }
  state.counters["colliding"] = data.n;
}
BENCHMARK(BM_RawFcl_BroadphaseCollideVsBoxFloor);

void BM_RawFcl_PerCapsuleDistanceVsPanelMesh(benchmark::State& state) {
  skeleton::Data d(model());
  skeleton::forwardKinematics(model(), d, cockpitPose());
  auto caps = capsuleObjects(d);
  fcl::CollisionObjectd panel(panelBvh(), panelPose());
  double dmin = 0;
  for (auto _ : state) {
    dmin = 1e9;
    for (auto& c : caps) {
      fcl::DistanceRequestd req;
      fcl::DistanceResultd res;
      fcl::distance(c.get(), &panel, req, res);
      dmin = std::min(dmin, res.min_distance);
    }
    benchmark::DoNotOptimize(dmin);
  }
  state.counters["capsules"] = static_cast<double>(caps.size());
  state.counters["min_distance"] = dmin;
}
BENCHMARK(BM_RawFcl_PerCapsuleDistanceVsPanelMesh)->Unit(benchmark::kMillisecond);



}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-collision", "configs/mannequins/male_50th.yaml", "configs/scenes/floor.yaml",
                         "configs/scenes/table.yaml", "configs/scenes/cockpit.yaml", "data/meshes/cockpit_panel.obj")
