// The YAML loader: the shipped default, every field, and errors "FILE:LINE: field 'a.b': message".
#include <gtest/gtest.h>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;
using mannequin::core::ConfigError;

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
      {"dt_s: -1\n", "cfg.yaml:1: field 'dt_s': must be > 0, got -1"},
      {"dt_s: 0.5\n", "cfg.yaml:1: field 'dt_s': must be <= 0.1 s"},
      {"dt_s: fast\n", "cfg.yaml:1: field 'dt_s': 'fast' is not a number"},
      {"dt_s: .nan\n", "cfg.yaml:1: field 'dt_s': '.nan' is not a finite number"},
      {"gravity: [0, 0]\n", "cfg.yaml:1: field 'gravity': expected a list of 3 numbers, got 2 values"},
      {"colour: red\n", "cfg.yaml:1: field 'colour': unknown key (expected one of: dt_s, gravity"},
      {"b_a:\n  joints: 0\n", "cfg.yaml:2: field 'b_a.joints': must be > 0, got 0"},
      {"b_a:\n  coordinates: {knee_l: -1}\n", "cfg.yaml:2: field 'b_a.coordinates.knee_l': must be > 0, got -1"},
      {"internal:\n  posture: sitting\n", "cfg.yaml:2: field 'internal.posture': expected standing or neutral, got 'sitting'"},
      {"internal:\n  energy_observer: {alpha_min: 2}\n", "cfg.yaml:2: field 'internal.energy_observer.alpha_min': 2 is outside [0, 1]"},
      {"projector: qr\n", "cfg.yaml:1: field 'projector': expected ldlt or svd, got 'qr'"},
      {"rank_tolerance: 2\n", "cfg.yaml:1: field 'rank_tolerance': must be in (0, 1)"},
      {"control_frames:\n  - name: a\n    stiffness: [1, 2, 3]\n",
       "cfg.yaml:3: field 'control_frames[0].stiffness': expected a list of 6 numbers, got 3 values"},
      {"control_frames:\n  - name: a\n    stiffness: 5\n", "cfg.yaml:3: field 'control_frames[0].stiffness': expected 6 numbers"},
      {"control_frames:\n  - name: a\n    stiffness: [1, 2, 3, 4, 5, -6]\n",
       "cfg.yaml:3: field 'control_frames[0].stiffness[5]': must be >= 0, got -6"},
      {"control_frames:\n  - name: a\n", "cfg.yaml:2: field 'control_frames[0]': missing key 'stiffness'"},
      {"control_frames:\n  - stiffness: [1,1,1,1,1,1]\n", "cfg.yaml:2: field 'control_frames[0]': missing required key 'name'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n",
       "cfg.yaml:4: field 'control_frames[1].name': duplicate control frame 'a'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    priority: 1.5\n",
       "cfg.yaml:4: field 'control_frames[0].priority': '1.5' is not an integer"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    priority: 101\n",
       "cfg.yaml:4: field 'control_frames[0].priority': 101 is outside [0, 100]"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    stifness: 3\n",
       "cfg.yaml:4: field 'control_frames[0].stifness': unknown key"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    offset: {xyz: [0, 0], rpy_deg: [0, 0, 0]}\n",
       "cfg.yaml:4: field 'control_frames[0].offset.xyz': expected [x, y, z], got 2 values"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism: {type: hinge}\n",
       "cfg.yaml:4: field 'control_frames[0].mechanism.type': unknown mechanism type 'hinge'"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: curve\n      points: [[0,0,0]]\n",
       "cfg.yaml:5: field 'control_frames[0].mechanism': virtual mechanism: a curve needs at least 2 points"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: prismatic\n      limits: [[1, 0]]\n",
       "cfg.yaml:6: field 'control_frames[0].mechanism.limits[0]': lower > upper"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: prismatic\n      limits: [[.nan, 0]]\n",
       "cfg.yaml:6: field 'control_frames[0].mechanism.limits[0][0]': '.nan' is not a number"},
      {"control_frames:\n  - name: a\n    stiffness: [1,1,1,1,1,1]\n    mechanism:\n      type: prismatic\n      normal_force: 3\n",
       "cfg.yaml:6: field 'control_frames[0].mechanism.normal_force': only for a plane"},
      {"control_frames: [\n", "cfg.yaml:2: YAML syntax error"},
  };
  for (const Case& c : cases) {
    const std::string m = errorOf(c.yaml);
    EXPECT_NE(m.find(c.expect), std::string::npos) << "yaml:\n" << c.yaml << "got: " << m;
  }
  EXPECT_THROW(loadControllerConfig("/nonexistent/control.yaml"), ConfigError);
  try {
    loadControllerConfig("/nonexistent/control.yaml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/control.yaml:0: cannot read the file", 0), 0u) << e.what();
  }
  const MechanismConfig m = parseMechanismConfig("type: plane\nnormal_force: 15\nstiffness: {translation: 100}\n", "m.yaml");
  EXPECT_DOUBLE_EQ(m.spec.force(3), -15);
  // a mechanism block inside another file keeps that file's lines and the block's path
  const auto scenario = mannequin::core::ConfigNode::parse("task:\n  mechanism:\n    type: plane\n    frction: 1\n", "s.yaml");
  try {
    parseMechanismConfig(scenario["task"]["mechanism"]);
    ADD_FAILURE() << "no error for an unknown mechanism key";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:4: field 'task.mechanism.frction': unknown key"), std::string::npos) << e.what();
  }
}
