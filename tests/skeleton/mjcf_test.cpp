// skeleton::toMjcf: the MJCF export of a mannequin (bench-step's MuJoCo comparison). Without MuJoCo:
// the document is well-formed XML with one body and one joint per joint of the tree and the segments'
// masses; with MuJoCo (MANNEQUIN_HAVE_MUJOCO): MuJoCo loads it, its sizes and total mass match ours,
// and its forward kinematics at our standing configuration (mjcfQpos) puts every body where ours does.
#include "../common/source.hpp"
#include "mannequin/skeleton/mjcf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <unistd.h>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/dynamics.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/math/so3.hpp"

#ifdef MANNEQUIN_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

using namespace mannequin::skeleton;

namespace {

using mannequin::testing::mannequinConfigPath;

/// One element of a minimal XML reader (no text content, no entities beyond attribute values: what
/// toMjcf writes), enough to check nesting and read attributes.
struct Element {
  std::string tag;
  std::map<std::string, std::string> attrs;
  std::vector<Element> children;
};

/// Parses `xml` (comments skipped); sets `error` on a malformed document.
Element parseXml(const std::string& xml, std::string& error) {
  std::vector<Element> stack;
  stack.push_back({"#document", {}, {}});
  std::size_t i = 0;
  auto fail = [&](const std::string& what) {
    if (error.empty()) error = what + " at offset " + std::to_string(i);
  };
  while (error.empty()) {
    i = xml.find('<', i);
    if (i == std::string::npos) break;
    if (xml.compare(i, 4, "<!--") == 0) {
      const std::size_t e = xml.find("-->", i);
      if (e == std::string::npos) fail("unterminated comment");
      i = e + 3;
      continue;
    }
    const std::size_t e = xml.find('>', i);
    if (e == std::string::npos) {
      fail("unterminated tag");
      break;
    }
    std::string body = xml.substr(i + 1, e - i - 1);
    i = e + 1;
    if (!body.empty() && body[0] == '/') {  // closing tag
      if (stack.size() < 2 || stack.back().tag != body.substr(1)) {
        fail("closing </" + body.substr(1) + "> does not match <" + stack.back().tag + ">");
        break;
      }
      Element done = std::move(stack.back());
      stack.pop_back();
      stack.back().children.push_back(std::move(done));
      continue;
    }
    const bool self_closing = !body.empty() && body.back() == '/';
    if (self_closing) body.pop_back();
    Element el;
    std::size_t k = body.find_first_of(" \n\t");
    el.tag = body.substr(0, k);
    while (k != std::string::npos && error.empty()) {
      k = body.find_first_not_of(" \n\t", k);
      if (k == std::string::npos) break;
      const std::size_t eq = body.find('=', k);
      if (eq == std::string::npos || eq + 1 >= body.size() || body[eq + 1] != '"') {
        fail("bad attribute in <" + el.tag + ">");
        break;
      }
      const std::size_t close = body.find('"', eq + 2);
      if (close == std::string::npos) {
        fail("unterminated attribute value in <" + el.tag + ">");
        break;
      }
      const std::string name = body.substr(k, eq - k);
      if (el.attrs.count(name)) fail("duplicate attribute " + name + " in <" + el.tag + ">");
      el.attrs[name] = body.substr(eq + 2, close - eq - 2);
      k = close + 1;
    }
    if (self_closing) stack.back().children.push_back(std::move(el));
    else stack.push_back(std::move(el));
  }
  if (error.empty() && stack.size() != 1) error = "unclosed <" + stack.back().tag + ">";
  return stack.front();
}

struct Counts {
  int bodies = 0, hinges = 0, balls = 0, free = 0, geoms = 0;
  double mass = 0;
};

void count(const Element& e, Counts& c) {
  if (e.tag == "body") ++c.bodies;
  if (e.tag == "freejoint") ++c.free;
  if (e.tag == "joint") (e.attrs.at("type") == "ball" ? c.balls : c.hinges) += 1;
  if (e.tag == "geom" && e.attrs.count("name") && e.attrs.at("name") != "floor") ++c.geoms;
  if (e.tag == "inertial") c.mass += std::stod(e.attrs.at("mass"));
  for (const Element& ch : e.children) count(ch, c);
}

/// A random tree as test_models::makeRandomTree (free root, balls and revolutes with random placements
/// and axes, a massive segment per joint, parents at random: the index order is not depth first), its
/// names appended rather than concatenated (g++ 12 reports a false -Wrestrict on `"j" + to_string(i)`
/// inlined here).
Model randomTree(unsigned seed, int njoints) {
  std::mt19937 g(seed);
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0.1, 2.0);
  auto v3 = [&] { return Vector3(n(g), n(g), n(g)); };
  auto name = [](char c, int i) {
    std::string s(1, c);
    s.append(std::to_string(i));
    return s;
  };
  Model m;
  m.name = "random";
  m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  for (int i = 1; i < njoints; ++i) {
    std::uniform_int_distribution<int> parent(0, i - 1);
    const SE3 placement(mannequin::math::expSO3(v3()), 0.3 * v3());
    m.addJoint(name('j', i), i % 3 == 0 ? JointType::kBall : JointType::kRevolute, parent(g), placement, v3());
  }
  for (int i = 0; i < njoints; ++i) {
    Segment s;
    s.name = name('s', i);
    s.joint = i;
    s.mass = u(g);
    s.com = 0.2 * v3();
    s.inertia = Matrix3::Identity() * 0.01;
    s.capsule.b = 0.1 * v3();
    s.capsule.radius = 0.02;
    m.addSegment(s);
  }
  return m;
}

int massless(const Model& m) {
  int n = 0;
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    bool has_mass = false, has_seg = false;
    for (const Segment& s : m.segments)
      if (s.joint == static_cast<int>(j)) {
        has_seg = true;
        has_mass = has_mass || s.mass > 0;
        if (!(s.mass > 0)) ++n;
      }
    if (!has_seg && m.joints[j].type != JointType::kFreeFlyer) ++n;
  }
  return n;
}

}  // namespace

TEST(Mjcf, MannequinIsWellFormedWithTheModelsJointsAndMass) {
  const Model model = buildMannequin(loadMannequinSpec(mannequinConfigPath("male_50th.yaml")));
  const MjcfOptions opt;
  std::string error;
  const Element doc = parseXml(toMjcf(model, opt), error);
  ASSERT_EQ(error, "");
  ASSERT_EQ(doc.children.size(), 1u);
  const Element& root = doc.children[0];
  EXPECT_EQ(root.tag, "mujoco");
  EXPECT_EQ(root.attrs.at("model"), model.name);
  Counts c;
  count(root, c);
  int balls = 0, hinges = 0, capsules = 0;
  for (const Joint& j : model.joints) (j.type == JointType::kBall ? balls : hinges) += j.type != JointType::kFreeFlyer;
  for (const Segment& s : model.segments) capsules += s.capsule.radius > 0;
  EXPECT_EQ(c.bodies, static_cast<int>(model.joints.size()));  // one segment per joint at most here
  EXPECT_EQ(c.free, 1);
  EXPECT_EQ(c.balls, balls);
  EXPECT_EQ(c.hinges, hinges);
  EXPECT_EQ(c.geoms, capsules);
  EXPECT_GT(massless(model), 0);  // the clavicles: the massless_mass path is exercised
  EXPECT_NEAR(c.mass, model.totalMass() + massless(model) * opt.massless_mass, 1e-9);
  EXPECT_NEAR(c.mass, 78.5, 1e-4);  // configs/mannequins/male_50th.yaml mass_kg
}

TEST(Mjcf, RandomTreeNestsBodiesAsTheJointTree) {
  const Model model = randomTree(7, 15);
  std::string error;
  const Element doc = parseXml(toMjcf(model), error);
  ASSERT_EQ(error, "");
  // each joint's body is a direct child of its parent joint's body
  std::map<std::string, std::string> parent_of;
  std::vector<std::pair<const Element*, std::string>> pending{{&doc.children.at(0), ""}};
  while (!pending.empty()) {
    auto [e, parent] = pending.back();
    pending.pop_back();
    for (const Element& ch : e->children) {
      if (ch.tag == "worldbody") pending.push_back({&ch, ""});
      if (ch.tag == "body") {
        parent_of[ch.attrs.at("name")] = parent;
        pending.push_back({&ch, ch.attrs.at("name")});
      }
    }
  }
  for (const Joint& j : model.joints) {
    ASSERT_TRUE(parent_of.count(j.name)) << j.name;
    EXPECT_EQ(parent_of[j.name], j.parent < 0 ? "" : model.joints[static_cast<std::size_t>(j.parent)].name) << j.name;
  }
}

TEST(Mjcf, QposHasAQuaternionPerBallAndTheFreeFlyersPose) {
  const Model model = buildMannequin(loadMannequinSpec(mannequinConfigPath("male_50th.yaml")));
  const VectorX q = standingConfiguration(model);
  const std::vector<double> qpos = mjcfQpos(model, q);
  int balls = 0;
  for (const Joint& j : model.joints) balls += j.type == JointType::kBall;
  ASSERT_EQ(static_cast<int>(qpos.size()), model.nq + 1 + balls);
  Data d(model);
  forwardKinematics(model, d, q);
  EXPECT_NEAR(qpos[0], d.oMi[0].p.x(), 1e-12);
  EXPECT_NEAR(qpos[2], d.oMi[0].p.z(), 1e-12);
  EXPECT_NEAR(std::hypot(std::hypot(qpos[3], qpos[4]), std::hypot(qpos[5], qpos[6])), 1.0, 1e-12);
  EXPECT_THROW(mjcfQpos(model, VectorX::Zero(model.nq - 1)), std::invalid_argument);
}

#ifdef MANNEQUIN_HAVE_MUJOCO
namespace {
/// Loads `xml` in MuJoCo (through a temporary file); nullptr and `error` on failure.
mjModel* loadMujoco(const std::string& xml, std::string& error) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mannequin_mjcf_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  std::filesystem::remove(path);
  error = err;
  return m;
}

/// randomTree(seed, 15) and its MJCF loaded in MuJoCo with an mjData; m is nullptr (error says why) when
/// MuJoCo refused it. Frees both however the test ends.
struct MujocoTree {
  explicit MujocoTree(unsigned seed)
      : model(randomTree(seed, 15)), m(loadMujoco(toMjcf(model), error)), d(m ? mj_makeData(m) : nullptr) {}
  ~MujocoTree() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
  MujocoTree(const MujocoTree&) = delete;
  MujocoTree& operator=(const MujocoTree&) = delete;
  Model model;
  std::string error;
  mjModel* m;
  mjData* d;
};
}  // namespace

TEST(MjcfMujoco, LoadsWithOurSizesMassAndForwardKinematics) {
  const Model model = buildMannequin(loadMannequinSpec(mannequinConfigPath("male_50th.yaml")));
  const MjcfOptions opt;
  std::string error;
  mjModel* m = loadMujoco(toMjcf(model, opt), error);
  ASSERT_NE(m, nullptr) << error;
  int balls = 0;
  for (const Joint& j : model.joints) balls += j.type == JointType::kBall;
  EXPECT_EQ(m->nv, model.nv);
  EXPECT_EQ(m->nq, model.nq + 1 + balls);
  EXPECT_EQ(m->nbody, static_cast<int>(model.joints.size()) + 1);  // + the world
  EXPECT_NEAR(mj_getTotalmass(m), model.totalMass() + massless(model) * opt.massless_mass, 1e-9);
  // forward kinematics at the standing configuration: body frames and the whole-body CoM
  const VectorX q = standingConfiguration(model);
  const std::vector<double> qpos = mjcfQpos(model, q);
  ASSERT_EQ(static_cast<int>(qpos.size()), m->nq);
  mjData* d = mj_makeData(m);
  for (int i = 0; i < m->nq; ++i) d->qpos[i] = qpos[static_cast<std::size_t>(i)];
  mj_kinematics(m, d);
  mj_comPos(m, d);
  Data ours(model);
  forwardKinematics(model, ours, q);
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const int b = mj_name2id(m, mjOBJ_BODY, model.joints[j].name.c_str());
    ASSERT_GE(b, 1) << model.joints[j].name;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(d->xpos[3 * b + k], ours.oMi[j].p[k], 1e-9) << model.joints[j].name;
      for (int l = 0; l < 3; ++l) EXPECT_NEAR(d->xmat[9 * b + 3 * k + l], ours.oMi[j].R(k, l), 1e-9) << model.joints[j].name;
    }
  }
  const Vector3 com = centerOfMass(model, ours);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(d->subtree_com[3 + k], com[k], 1e-6);  // body 1: the root's subtree
  // the feet rest on the floor in the standing pose: MuJoCo finds floor contacts there and none elsewhere
  mj_collision(m, d);
  EXPECT_GT(d->ncon, 0);
  const int floor = mj_name2id(m, mjOBJ_GEOM, "floor");
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    const int other = c.geom1 == floor ? c.geom2 : c.geom1;
    EXPECT_TRUE(c.geom1 == floor || c.geom2 == floor);
    EXPECT_EQ(std::string(mj_id2name(m, mjOBJ_GEOM, other)).rfind("foot", 0), 0u) << mj_id2name(m, mjOBJ_GEOM, other);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
}
#endif

#ifdef MANNEQUIN_HAVE_MUJOCO
TEST(MjcfMujoco, RandomTreeForwardKinematicsMatchesAtRandomConfigurations) {
  // rotated placements, random axes, a tree whose index order is not depth first: mjcfQpos's order
  for (unsigned seed : {3u, 11u}) {
    const MujocoTree tree(seed);
    ASSERT_NE(tree.m, nullptr) << tree.error;
    const Model& model = tree.model;
    mjModel* m = tree.m;
    mjData* d = tree.d;
    Data ours(model);
    std::srand(seed);
    for (int trial = 0; trial < 5; ++trial) {
      const VectorX q = VectorX::Random(model.nq);
      const std::vector<double> qpos = mjcfQpos(model, q);
      ASSERT_EQ(static_cast<int>(qpos.size()), m->nq);
      for (int i = 0; i < m->nq; ++i) d->qpos[i] = qpos[static_cast<std::size_t>(i)];
      mj_kinematics(m, d);
      forwardKinematics(model, ours, q);
      for (std::size_t j = 0; j < model.joints.size(); ++j) {
        const int b = mj_name2id(m, mjOBJ_BODY, model.joints[j].name.c_str());
        ASSERT_GE(b, 1);
        for (int k = 0; k < 3; ++k) {
          EXPECT_NEAR(d->xpos[3 * b + k], ours.oMi[j].p[k], 1e-9) << seed << " " << model.joints[j].name;
          for (int l = 0; l < 3; ++l) EXPECT_NEAR(d->xmat[9 * b + 3 * k + l], ours.oMi[j].R(k, l), 1e-9);
        }
      }
    }
  }
}
#endif

#ifdef MANNEQUIN_HAVE_MUJOCO
TEST(MjcfMujoco, InverseDynamicsMatchesMujocosRneAtRandomStates) {
  // rnea (skeleton/dynamics.hpp) against MuJoCo's recursive Newton-Euler (mj_rne: M(q) q̈ + bias, gravity
  // included) on the same tree at random (q, v, a). Coordinates: revolute and ball velocities are MuJoCo's
  // (a ball's: the child's angular velocity in its own frame); the free flyer's v = (ω_b, v_b) is the root's
  // body twist, MuJoCo's free joint (ṗ in the world, ω_b), so with R the root's orientation
  //   qvel = (R v_b, ω_b),  qacc = (R (v̇_b + ω_b × v_b), ω̇_b),  and its force (R f_b, n_b) for τ = (n_b, f_b).
  for (unsigned seed : {3u, 11u}) {
    const MujocoTree tree(seed);
    ASSERT_NE(tree.m, nullptr) << tree.error;
    const Model& model = tree.model;
    mjModel* m = tree.m;
    mjData* d = tree.d;
    ASSERT_EQ(m->nv, model.nv);
    Data ours(model);
    std::srand(seed);
    std::vector<mjtNum> res(static_cast<std::size_t>(m->nv));
    for (int trial = 0; trial < 5; ++trial) {
      const VectorX q = VectorX::Random(model.nq);
      const VectorX v = 2.0 * VectorX::Random(model.nv);
      const VectorX a = 5.0 * VectorX::Random(model.nv);
      const VectorX& tau = rnea(model, ours, q, v, a, Vector3(0, 0, -9.81));
      const std::vector<double> qpos = mjcfQpos(model, q);
      for (int i = 0; i < m->nq; ++i) d->qpos[i] = qpos[static_cast<std::size_t>(i)];
      // per joint: MuJoCo's dof address, our velocity index, and the expected generalized force
      std::vector<double> expected(static_cast<std::size_t>(m->nv));
      for (const Joint& j : model.joints) {
        const int b = mj_name2id(m, mjOBJ_BODY, j.name.c_str());
        ASSERT_GE(b, 1) << j.name;
        const int dof = m->jnt_dofadr[m->body_jntadr[b]];
        if (j.type == JointType::kFreeFlyer) {
          const Matrix3 R = mannequin::math::expSO3(q.segment<3>(j.idx_q + 3));
          const Vector3 w = v.segment<3>(j.idx_v), vb = v.segment<3>(j.idx_v + 3);
          const Vector3 dw = a.segment<3>(j.idx_v), dvb = a.segment<3>(j.idx_v + 3);
          const Vector3 pdot = R * vb, pddot = R * (dvb + w.cross(vb));
          const Vector3 f = R * tau.segment<3>(j.idx_v + 3);
          for (int k = 0; k < 3; ++k) {
            d->qvel[dof + k] = pdot[k];
            d->qvel[dof + 3 + k] = w[k];
            d->qacc[dof + k] = pddot[k];
            d->qacc[dof + 3 + k] = dw[k];
            expected[static_cast<std::size_t>(dof + k)] = f[k];
            expected[static_cast<std::size_t>(dof + 3 + k)] = tau[j.idx_v + k];
          }
        } else {
          for (int k = 0; k < j.nv; ++k) {
            d->qvel[dof + k] = v[j.idx_v + k];
            d->qacc[dof + k] = a[j.idx_v + k];
            expected[static_cast<std::size_t>(dof + k)] = tau[j.idx_v + k];
          }
        }
      }
      mj_fwdPosition(m, d);
      mj_fwdVelocity(m, d);  // cvel and cdof_dot, which mj_rne reads
      mj_rne(m, d, 1, res.data());
      for (int i = 0; i < m->nv; ++i) {
        const double e = expected[static_cast<std::size_t>(i)];
        EXPECT_NEAR(res[static_cast<std::size_t>(i)], e, 1e-8 * (1.0 + std::abs(e)))
            << "seed " << seed << " trial " << trial << " dof " << i;
      }
    }
  }
}
#endif
