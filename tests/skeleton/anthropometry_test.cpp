#include "../common/source.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin::skeleton;
using mannequin::core::ConfigError;

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;

using mannequin::testing::mannequinConfigPath;

std::string configError(const std::string& yaml) {
  try {
    parseMannequinSpec(yaml, "test.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

struct Built {
  Model m;
  Data d;
  explicit Built(const MannequinSpec& s) : m(buildMannequin(s)), d(m) {}
  void at(const VectorX& q) {
    computeJointJacobians(m, d, q);
    jacobianCenterOfMass(m, d);
  }
  Vector3 joint(const std::string& n) const { return d.oMi[m.jointIndex(n)].p; }
};
}  // namespace

TEST(Anthropometry, ShippedConfigsBuildWithTheirStatureAndMass) {
  for (const char* file : {"female_05th.yaml", "male_50th.yaml", "male_95th.yaml"}) {
    SCOPED_TRACE(file);
    const MannequinSpec spec = loadMannequinSpec(mannequinConfigPath(file));
    Built b(spec);
    EXPECT_NEAR(b.m.totalMass(), spec.mass, 1e-9);  // de Leva fractions sum to 1
    b.at(standingConfiguration(b.m));
    // standing: soles on the floor, vertex at the stature
    EXPECT_NEAR(b.d.oMf[b.m.frameIndex("sole_l")].p.z(), 0.0, 1e-12);
    EXPECT_NEAR(b.d.oMf[b.m.frameIndex("head_top")].p.z(), spec.stature, 1e-12);
    // whole-body CoM of an upright adult: about 55–57 % of stature, on the sagittal plane
    EXPECT_GT(b.d.com.z(), 0.53 * spec.stature);
    EXPECT_LT(b.d.com.z(), 0.60 * spec.stature);
    EXPECT_NEAR(b.d.com.y(), 0.0, 1e-12);
    // every segment with mass has a positive capsule, and the CoM lies between its ends
    for (const Segment& s : b.m.segments) {
      EXPECT_GT(s.capsule.radius, 0.005) << s.name;
      EXPECT_LT(s.capsule.radius, 0.25) << s.name;
    }
  }
}

TEST(Anthropometry, DegreesOfFreedomLikeThesisFigure15) {
  MannequinSpec spec;
  Built b(spec);
  EXPECT_EQ(b.m.nv - 6, 37);  // internal DoF without toes (thesis Fig. 1.5 has 36)
  spec.toes = true;
  EXPECT_EQ(buildMannequin(spec).nv - 6, 39);
  for (const char* f : {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r", "palm_l", "sole_r"})
    EXPECT_GE(b.m.findFrame(f), 0) << f;
}

TEST(Anthropometry, SegmentParametersFollowDeLeva) {
  MannequinSpec spec;
  spec.sex = Sex::kMale;
  spec.mass = 80.0;
  spec.stature = 1.741;  // de Leva's reference stature: lengths are the table's
  Built b(spec);
  const Segment& thigh = b.m.segments[b.m.segmentIndex("thigh_l")];
  EXPECT_NEAR(thigh.mass, 0.1416 * 80.0, 1e-12);
  EXPECT_NEAR(thigh.length, 0.4222, 1e-12);
  EXPECT_NEAR(-thigh.com.z(), 0.4095 * 0.4222, 1e-12);                      // from the hip joint centre
  EXPECT_NEAR(thigh.inertia(0, 0), 0.1416 * 80.0 * std::pow(0.329 * 0.4222, 2), 1e-12);
  EXPECT_NEAR(thigh.inertia(2, 2), 0.1416 * 80.0 * std::pow(0.149 * 0.4222, 2), 1e-12);
  spec.sex = Sex::kFemale;
  const Model f = buildMannequin(spec);
  EXPECT_NEAR(f.segments[f.segmentIndex("thigh_r")].mass, 0.1478 * 80.0, 1e-12);
  // lengths scale with stature
  spec.stature = 1.2 * 1.735;
  const Model big = buildMannequin(spec);
  EXPECT_NEAR(big.segments[big.segmentIndex("shank_l")].length, 1.2 * 0.4323, 1e-12);
}

TEST(Anthropometry, LimitsAreTheRangeOfMotionTableMirrored) {
  const Model m = buildMannequin(MannequinSpec{});
  const auto names = m.coordinateNames();
  const auto limits = [&](const std::string& c) {
    const int i = static_cast<int>(std::find(names.begin(), names.end(), c) - names.begin());
    return std::pair{m.lower_limit(i) / kDeg, m.upper_limit(i) / kDeg};
  };
  EXPECT_NEAR(limits("knee_l").first, 0.0, 1e-9);
  EXPECT_NEAR(limits("knee_l").second, 135.0, 1e-9);
  EXPECT_NEAR(limits("elbow_r").second, 150.0, 1e-9);
  // hip abduction 45 / adduction 30 about +x on the left, mirrored to −x on the right
  EXPECT_NEAR(limits("hip_l.x").first, -30.0, 1e-9);
  EXPECT_NEAR(limits("hip_l.x").second, 45.0, 1e-9);
  EXPECT_NEAR(limits("hip_r.x").first, -45.0, 1e-9);
  EXPECT_NEAR(limits("hip_r.x").second, 30.0, 1e-9);
  EXPECT_NEAR(limits("hip_r.y").first, -120.0, 1e-9);  // flexion is about −y on both sides
  // the anatomical posture is within every limit
  const VectorX q = m.neutralConfiguration();
  EXPECT_TRUE(((q - m.lower_limit).array() >= 0).all());
  EXPECT_TRUE(((m.upper_limit - q).array() >= 0).all());
}

TEST(Anthropometry, PositiveAnglesMoveLimbsTheAnatomicalWay) {
  Built b(MannequinSpec{});
  const auto names = b.m.coordinateNames();
  const auto idx = [&](const std::string& c) { return static_cast<int>(std::find(names.begin(), names.end(), c) - names.begin()); };
  VectorX q = b.m.neutralConfiguration();
  b.at(q);
  const Vector3 ankle0 = b.joint("ankle_l"), wrist0_l = b.joint("wrist_l"), elbow0_r = b.joint("elbow_r"),
                knee0 = b.joint("knee_r");
  q(idx("knee_l")) = 90 * kDeg;         // knee flexion: the ankle goes backward
  q(idx("elbow_l")) = 90 * kDeg;        // elbow flexion: the wrist comes forward
  q(idx("shoulder_r.x")) = -90 * kDeg;  // right shoulder abduction (mirrored sign): elbow goes to the right
  q(idx("hip_r.y")) = -90 * kDeg;       // hip flexion: the knee comes forward
  b.at(q);
  EXPECT_LT(b.joint("ankle_l").x(), ankle0.x() - 0.3);
  EXPECT_GT(b.joint("wrist_l").x(), wrist0_l.x() + 0.2);
  EXPECT_LT(b.joint("elbow_r").y(), elbow0_r.y() - 0.2);
  EXPECT_GT(b.joint("knee_r").x(), knee0.x() + 0.3);
}

TEST(Anthropometry, BadConfigsNameFileLineAndKey) {
  const auto expectError = [](const std::string& yaml, const std::string& what) {
    const std::string e = configError(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "yaml:\n" << yaml << "got: " << e;
  };
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\nheight: 2\n", "test.yaml:4: field 'height': unknown key");
  expectError("sex: male\nstature_m: 18\nmass_kg: 80\n", "test.yaml:2: field 'stature_m': 18 is outside [0.5, 2.5]");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: heavy\n", "test.yaml:3: field 'mass_kg': 'heavy' is not a number");
  expectError("sex: male\nstature_m: .nan\nmass_kg: 80\n", "test.yaml:2: field 'stature_m': '.nan' is not a finite number");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\ndensity_kg_m3: 5\n", "test.yaml:4: field 'density_kg_m3': 5 is outside");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\ntoes: maybe\n", "test.yaml:4: field 'toes': 'maybe' is not true/false");
  expectError("sex: robot\nstature_m: 1.8\nmass_kg: 80\n", "test.yaml:1: field 'sex': expected male or female, got 'robot'");
  expectError("stature_m: 1.8\nmass_kg: 80\n", "test.yaml:1: field '<top>': missing required key 'sex'");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\njoint_limits_deg:\n  kneee_l: [0, 90]\n",
              "test.yaml:5: field 'joint_limits_deg.kneee_l': unknown coordinate 'kneee_l'");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\njoint_limits_deg:\n  knee_l: [90, 0]\n",
              "test.yaml:5: field 'joint_limits_deg.knee_l': [min, max] in degrees with min > max");
  expectError("sex: male\nstature_m: 1.8\nmass_kg: 80\njoint_limits_deg:\n  knee_l: [90]\n",
              "field 'joint_limits_deg.knee_l': expected a list of 2 numbers, got 1 values");
  expectError("sex: [male\n", "test.yaml:2: YAML syntax error");  // yaml-cpp reports the end of input
  expectError("- a\n- b\n", "test.yaml:1: expected a map");
  EXPECT_THROW(loadMannequinSpec("/nonexistent/mannequin.yaml"), ConfigError);
  try {
    loadMannequinSpec("/nonexistent/mannequin.yaml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/mannequin.yaml:0: cannot read the file", 0), 0u) << e.what();
  }
  // an override is applied
  const MannequinSpec s = parseMannequinSpec("sex: female\nstature_m: 1.6\nmass_kg: 55\njoint_limits_deg:\n  knee_l: [0, 90]\n", "t");
  const Model m = buildMannequin(s);
  EXPECT_NEAR(m.upper_limit(m.joints[m.jointIndex("knee_l")].idx_q), 90 * kDeg, 1e-12);
  // the API rejects absurd values too
  MannequinSpec bad;
  bad.mass = std::nan("");
  EXPECT_THROW(buildMannequin(bad), std::invalid_argument);
}

TEST(Anthropometry, BallJointsGetSwingTwistLimitsFromTheBoxesOrTheConfig) {
  const double kD = 3.14159265358979323846 / 180.0;
  const Model m = buildMannequin(parseMannequinSpec("sex: male\nstature_m: 1.75\nmass_kg: 75\n", "t.yaml"));
  // hip_l: box x [-30, 45], y [-120, 30], z [-45, 45]; twist axis −z (thigh hangs down)
  const BallLimit& hip = m.joints[m.jointIndex("hip_l")].ball_limit;
  ASSERT_TRUE(hip.enabled);
  EXPECT_LT((hip.twist_axis + Vector3::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(hip.swing_cx, 7.5 * kD, 1e-12);
  EXPECT_NEAR(hip.swing_a, 37.5 * kD, 1e-12);
  EXPECT_NEAR(hip.swing_cy, -45 * kD, 1e-12);
  EXPECT_NEAR(hip.swing_b, 75 * kD, 1e-12);
  EXPECT_NEAR(hip.twist_lower, -45 * kD, 1e-12);  // [−hi_z, −lo_z] about −z
  EXPECT_NEAR(hip.twist_upper, 45 * kD, 1e-12);
  // the neck's axis is +z (head above): twist = the z box
  EXPECT_LT((m.joints[m.jointIndex("neck")].ball_limit.twist_axis - Vector3::UnitZ()).norm(), 1e-12);
  // shoulder_l: the box's inscribed ellipse reaches past 150° (kMaxSwing): scaled about 0 to reach it
  const BallLimit& sh = m.joints[m.jointIndex("shoulder_l")].ball_limit;
  EXPECT_NEAR(sh.maxSwing(), BallLimit::kMaxSwing, 1e-6);
  EXPECT_NEAR(sh.swing_cx / sh.swing_a, 70.0 / 100.0, 1e-12);
  // explicit values in degrees
  const MannequinSpec spec = parseMannequinSpec(
      "sex: male\nstature_m: 1.75\nmass_kg: 75\nball_limits_deg:\n  shoulder_l: {swing_axes: [80, 90], swing_center: [50, "
      "-40], twist: [-80, 60]}\n",
      "t.yaml");
  const Model m2 = buildMannequin(spec);
  const BallLimit& s2 = m2.joints[m2.jointIndex("shoulder_l")].ball_limit;
  EXPECT_NEAR(s2.swing_a, 80 * kD, 1e-12);
  EXPECT_NEAR(s2.swing_cy, -40 * kD, 1e-12);
  EXPECT_NEAR(s2.twist_lower, -80 * kD, 1e-12);
  // errors name FILE:LINE and the key
  const auto err = [](const std::string& yaml) {
    try {
      parseMannequinSpec("sex: male\nstature_m: 1.75\nmass_kg: 75\nball_limits_deg:\n" + yaml, "t.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(err("  knee_l: {twist: [-10, 10]}\n").find("t.yaml:5: field 'ball_limits_deg.knee_l': 'knee_l' is not a ball"),
            std::string::npos);
  EXPECT_NE(err("  hip_l: {swing_axes: [170, 170]}\n").find("t.yaml:5: field 'ball_limits_deg.hip_l': the swing ellipse reaches"),
            std::string::npos);
  EXPECT_NE(err("  hip_l: {swing_center: [50, 0]}\n").find("must contain the rest direction"), std::string::npos);
  EXPECT_NE(err("  hip_l: {twist: [10, 20]}\n").find("twist range [lower, upper] must contain 0"), std::string::npos);
  EXPECT_NE(err("  hip_l: {swing_axes: [-1, 20]}\n").find("semi-axes must be > 0"), std::string::npos);
  EXPECT_NE(err("  hip_l: {twist_axis: [0, 0, 0]}\n").find("twist_axis"), std::string::npos);
  EXPECT_NE(err("  hip_l: {swing: [1, 2]}\n").find("t.yaml:5"), std::string::npos);
}
