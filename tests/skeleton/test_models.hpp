#pragma once
// Small models shared by the skeleton tests.
#include <random>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton::test_models {

/// A random tree mixing every joint type: free-flyer root, balls and revolutes with random
/// placements and axes, massive segments and a frame on every joint.
inline Model makeRandomTree(unsigned seed, int njoints = 12) {
  std::mt19937 g(seed);
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0.1, 2.0);
  auto v3 = [&] { return Vector3(n(g), n(g), n(g)); };
  // prefix + number, appended (GCC 12 warns falsely of -Wrestrict on "literal" + std::to_string at -O3)
  const auto named = [](const char* prefix, int i) {
    std::string out = prefix;
    out += std::to_string(i);
    return out;
  };
  Model m;
  m.name = "random";
  m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  for (int i = 1; i < njoints; ++i) {
    std::uniform_int_distribution<int> parent(0, i - 1);
    const SE3 placement(math::expSO3(v3()), 0.3 * v3());
    const JointType type = (i % 3 == 0) ? JointType::kBall : JointType::kRevolute;
    m.addJoint(named("j", i), type, parent(g), placement, v3());
  }
  for (int i = 0; i < njoints; ++i) {
    Segment s;
    s.name = named("s", i);
    s.joint = i;
    s.mass = u(g);
    s.com = 0.2 * v3();
    s.inertia = Matrix3::Identity() * 0.01;
    m.addSegment(s);
    m.addFrame(named("f", i), i, SE3(math::expSO3(v3()), 0.2 * v3()));
  }
  return m;
}

inline VectorX randomConfiguration(const Model& m, unsigned seed, double scale = 1.0) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  VectorX q(m.nq);
  for (int i = 0; i < m.nq; ++i) q(i) = u(g);
  return q;
}

}  // namespace mannequin::skeleton::test_models
