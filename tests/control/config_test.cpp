// The YAML loader: the shipped default, every field, and errors "FILE:LINE: field: message".
#include <gtest/gtest.h>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

namespace {
std::string errorOf(const std::string& yaml) {
  try {
    parseControllerConfig(yaml, "cfg.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST(ControlConfig, DefaultFileHasTheSixFramesAndTwoLevels) {
  const ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  ASSERT_EQ(c.frames.size(), 6u);
  EXPECT_DOUBLE_EQ(c.dt, 0.001);
  EXPECT_EQ(c.gravity, Vector3(0, 0, -9.81));
  EXPECT_DOUBLE_EQ(c.b_a.root_linear, 300);
  EXPECT_EQ(c.projector, ProjectorMethod::kLdlt);
  std::set<std::string> names;
  std::set<int> levels;
  for (const auto& f : c.frames) names.insert(f.name), levels.insert(f.priority);
  EXPECT_EQ(names, (std::set<std::string>{"hand_l", "hand_r", "foot_l", "foot_r", "pelvis", "head"}));
  EXPECT_EQ(levels.size(), 2u);
  EXPECT_NE(c.frames[0].where.find("default.yaml:"), std::string::npos);
}

TEST(ControlConfig, EveryFieldIsRead) {
  const ControllerConfig c = parseControllerConfig(R"(
dt_s: 0.002
gravity: [0, 0, -1.62]
b_a: {root_linear: 100, root_angular: 20, joints: 3, coordinates: {knee_l: 7}}
internal:
  enabled: false
  stiffness: 80
  damping: 1
  coordinates: {elbow_r: 0}
  posture: neutral
  projection: none
  energy_observer: {enabled: false, budget_J: 2, decay_per_s: 1, recovery_per_s: 0.5, alpha_min: 0.1}
projector: svd
coupling_error: se3
rank_tolerance: 1.0e-7
control_frames:
  - name: drill
    frame: hand_r
    offset: {xyz: [0.02, 0, -0.09], rpy_deg: [0, 90, 0]}
    stiffness: {rotation: 100, translation: 2000}
    damping: [1, 2, 3, 4, 5, 6]
    priority: 2
    weight: 0.5
    enabled: false
    mechanism:
      type: sliding_pivot
      origin: {xyz: [0.4, -0.2, 1.1], rpy_deg: [0, 90, 0]}
      limits: [[-0.1, 0.05], [-.inf, .inf]]
      force: [0, 0]
      friction: 2
      stiffness: [2000, 2000, 2000, 20000, 20000, 20000]
      damping: {rotation: 20, translation: 200}
      enabled: true
)",
                                                   "t.yaml");
  EXPECT_DOUBLE_EQ(c.dt, 0.002);
  EXPECT_DOUBLE_EQ(c.gravity.z(), -1.62);
  EXPECT_DOUBLE_EQ(c.b_a.coordinates.at("knee_l"), 7);
  EXPECT_FALSE(c.internal.enabled);
  EXPECT_EQ(c.internal.posture, "neutral");
  EXPECT_EQ(c.internal.projection, InternalProjection::kNone);
  EXPECT_DOUBLE_EQ(c.internal.observer.alpha_min, 0.1);
  EXPECT_EQ(c.projector, ProjectorMethod::kSvd);
  EXPECT_EQ(c.coupling_error, CouplingError::kSE3);
  ASSERT_EQ(c.frames.size(), 1u);
  const ControlFrameConfig& f = c.frames[0];
  EXPECT_EQ(f.frame, "hand_r");
  EXPECT_LT((f.offset.R.col(2) - Vector3::UnitX()).norm(), 1e-12);  // rpy (0, 90°, 0) turns z onto x
  EXPECT_DOUBLE_EQ(f.stiffness(0), 100);
  EXPECT_DOUBLE_EQ(f.stiffness(5), 2000);
  EXPECT_DOUBLE_EQ(f.damping(3), 4);
  EXPECT_EQ(f.priority, 2);
  EXPECT_FALSE(f.enabled);
  ASSERT_TRUE(f.mechanism.has_value());
  EXPECT_EQ(f.mechanism->spec.type, MechanismType::kSlidingPivot);
  EXPECT_DOUBLE_EQ(f.mechanism->spec.upper(0), 0.05);
  EXPECT_TRUE(std::isinf(f.mechanism->spec.upper(1)));
  EXPECT_DOUBLE_EQ(f.mechanism->damping(4), 200);
  EXPECT_TRUE(f.mechanism->enabled);
  // and it builds on the mannequin, the mechanism attached and enabled
  Controller ctl(male50(), c);
  EXPECT_TRUE(ctl.frame(0).mechanism_enabled);
  EXPECT_EQ(ctl.mechanism(0).dim(), 2);
}

TEST(ControlConfig, ErrorsNameFileLineAndField) {
  struct Case {
    const char* yaml;
    const char* expect;
  };
  const Case cases[] = {
      {"dt_s: -1\n", "cfg.yaml:1: dt_s: must be > 0"},
      {"dt_s: fast\n", "cfg.yaml:1: dt_s: expected a number"},
      {"dt_s: .nan\n", "cfg.yaml:1: dt_s: must be finite"},
      {"gravity: [0, 0]\n", "cfg.yaml:1: gravity: expected a list of 3 numbers"},
      {"colour: red\n", "cfg.yaml:1: config: unknown key 'colour'"},
      {"b_a:\n  joints: 0\n", "cfg.yaml:2: b_a.joints: must be > 0"},
      {"internal:\n  posture: sitting\n", "cfg.yaml:2: internal.posture"},
      {"projector: qr\n", "cfg.yaml:1: projector"},
      {"control_frames:\n  - name: a\n    stiffness: [1, 2, 3]\n", "cfg.yaml:3: control_frames[0].stiffness: expected a list of 6"},
      {"control_frames:\n  - name: a\n    stiffness: [1, 2, 3, 4, 5, -6]\n", "control_frames[0].stiffness[5]: must be >= 0"},
      {"control_frames:\n  - name: a\n", "cfg.yaml:2: control_frames[0]: missing key 'stiffness'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n",
       "cfg.yaml:4: control_frames[1].name: duplicate"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    priority: 1.5\n", "control_frames[0].priority"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    stifness: 3\n", "unknown key 'stifness'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism: {type: hinge}\n",
       "control_frames[0].mechanism.type: unknown mechanism type 'hinge'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: curve\n      points: [[0,0,0]]\n",
       "cfg.yaml:5: control_frames[0].mechanism: virtual mechanism: a curve needs at least 2 points"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: prismatic\n      limits: [[1, 0]]\n",
       "control_frames[0].mechanism.limits[0]: lower > upper"},
      {"control_frames: [\n", "cfg.yaml:2: invalid YAML"},
  };
  for (const Case& c : cases) {
    const std::string m = errorOf(c.yaml);
    EXPECT_NE(m.find(c.expect), std::string::npos) << "yaml:\n" << c.yaml << "got: " << m;
  }
  EXPECT_THROW(loadControllerConfig("/nonexistent/control.yaml"), ConfigError);
  try {
    loadControllerConfig("/nonexistent/control.yaml");
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/control.yaml:0:"), std::string::npos);
  }
  const MechanismConfig m = parseMechanismConfig("type: plane\nnormal_force: 15\nstiffness: {translation: 100}\n", "m.yaml");
  EXPECT_DOUBLE_EQ(m.spec.force(3), -15);
}
