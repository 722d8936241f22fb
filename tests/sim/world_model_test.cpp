// libs/sim: buildWorldModel (the World's constant description: resolved indices, sources, the
// controllers' gravity, the physics scene's materials and μ table, its checks) and a World built from it.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/collision/scene.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/sim/world_model.hpp"
#include "../common/mannequins.hpp"
#include "../common/pose.hpp"
#include "../common/source.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace world_model_test {
using mannequin::testing::male50;
using mannequin::testing::sourcePath;

// A floor of wood and a table of steel; μ(skin, wood) = 0.8, μ(steel, wood) = 0.3, 0.1 elsewhere.
const char* kScene = R"(
name: materials
default_material: wood
friction:
  default: 0.1
  pairs:
    - {a: skin, b: wood, mu: 0.8}
    - {a: steel, b: wood, mu: 0.3}
    - {a: rubber, b: glass, mu: 0.9}
bodies:
  - name: floor
    shape: {type: plane, normal: [0, 0, 1], offset: 0}
  - name: table
    material: steel
    shape: {type: box, size: [1, 1, 0.05]}
    pose: {position: [2, 0, 0.7]}
)";

MannequinSetup setup(const std::string& name, const std::string& source, bool controller) {
  MannequinSetup s;
  s.name = name;
  s.model = male50();
  s.frames = {{"pelvis", "pelvis"}, {"hand_l", "hand_l"}, {"head", "head"}};
  s.mocap_source = source;
  if (controller) {
    s.controller = control::loadControllerConfig(sourcePath("configs/control/mocap.yaml"));
    s.controller->gravity = math::Vector3(0, 0, -1);  // replaced by physics.gravity when physics is on
  }
  return s;
}

SimConfig physicsConfig() {
  SimConfig c;
  c.physics.enabled = true;
  c.physics.gravity = math::Vector3(0, 0, -9.81);
  c.physics.scene = collision::parseScene(kScene, "materials.yaml");
  return c;
}

std::string refusal(std::vector<MannequinSetup> setups, const SimConfig& config) {
  try {
    (void)buildWorldModel(std::move(setups), config);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(WorldModel, ResolvesFramesSourcesAndTheControllersGravity) {
  std::vector<MannequinSetup> setups;
  setups.push_back(setup("a", "", true));
  setups.push_back(setup("b", "vicon", true));
  setups.push_back(setup("c", "vicon", true));
  const WorldModel wm = buildWorldModel(std::move(setups), physicsConfig());
  ASSERT_EQ(wm.sources, (std::vector<std::string>{"", "vicon"}));
  ASSERT_EQ(wm.mannequins.size(), 3u);
  EXPECT_EQ(wm.mannequins[0].source, 0);
  EXPECT_EQ(wm.mannequins[1].source, 1);
  EXPECT_EQ(wm.mannequins[2].source, 1);
  EXPECT_EQ(wm.findMannequin("c"), 2);
  EXPECT_EQ(wm.findMannequin("d"), -1);
  EXPECT_EQ(wm.findSource("vicon"), 1);
  EXPECT_EQ(wm.findSource("optitrack"), -1);
  for (const MannequinModel& mm : wm.mannequins) {
    ASSERT_EQ(mm.frame_indices.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(mm.frame_indices[i], mm.model.frameIndex(mm.control_frames[i].frame));
    EXPECT_EQ(mm.root_frame, mm.model.frameIndex("pelvis"));
    EXPECT_EQ(mm.q_standing, skeleton::standingConfiguration(mm.model));
    ASSERT_TRUE(mm.controller.has_value());
    EXPECT_EQ(mm.controller->gravity, math::Vector3(0, 0, -9.81));
    EXPECT_TRUE(mm.balance_frames.empty());  // the balance controller is off
  }
}

TEST(WorldModel, BuildsTheMaterialsAndTheFrictionTableOfTheScene) {
  std::vector<MannequinSetup> setups;
  setups.push_back(setup("a", "", true));
  const WorldModel wm = buildWorldModel(std::move(setups), physicsConfig());
  ASSERT_TRUE(wm.physics.has_value());
  const PhysicsModel& pm = *wm.physics;
  // the scene's default first, each material once, the segments' (PhysicsConfig::segment_material) last
  EXPECT_EQ(pm.materials, (std::vector<std::string>{"wood", "steel", "skin"}));
  EXPECT_EQ(pm.segment_material, 2);
  const int wood = pm.material("wood"), steel = pm.material("steel"), skin = pm.material("skin");
  EXPECT_EQ(pm.material("rubber"), -1);  // in the friction table, on no body
  const Eigen::MatrixXd& mu = pm.contacts.mu;
  ASSERT_EQ(mu.rows(), 3);
  ASSERT_EQ(mu.cols(), 3);
  EXPECT_EQ(mu(skin, wood), 0.8);
  EXPECT_EQ(mu(wood, skin), 0.8);
  EXPECT_EQ(mu(steel, wood), 0.3);
  EXPECT_EQ(mu(wood, steel), 0.3);
  EXPECT_EQ(mu(skin, steel), 0.1);
  EXPECT_EQ(mu(wood, wood), 0.1);
  // the physics' activation distance, not the scene file's
  EXPECT_EQ(pm.scene.activation_distance, wm.config.physics.activation_distance);
  ASSERT_EQ(pm.mannequin_options.size(), 1u);
  EXPECT_EQ(pm.mannequin_options[0].name, "a");
  EXPECT_EQ(pm.mannequin_options[0].margin, wm.config.physics.segment_margin);
}

TEST(WorldModel, TheSegmentPairsTouchingWhenStandingAreExcluded) {
  // with self collision on: standing, the thighs and the arms along the trunk are within the activation
  // distance, excluded from the self contacts; feet and head are far apart, not excluded
  std::vector<MannequinSetup> setups;
  setups.push_back(setup("a", "", true));
  SimConfig config = physicsConfig();
  config.physics.self_collision = true;
  const WorldModel wm = buildWorldModel(std::move(setups), config);
  EXPECT_TRUE(wm.physics->mannequin_options[0].self_collision);
  const auto& pairs = wm.physics->mannequin_options[0].exclude_pairs;
  const auto excluded = [&](const std::string& x, const std::string& y) {
    for (const auto& p : pairs)
      if ((p.first == x && p.second == y) || (p.first == y && p.second == x)) return true;
    return false;
  };
  EXPECT_FALSE(pairs.empty());
  for (const auto& p : pairs) {
    EXPECT_GE(wm.mannequins[0].model.findSegment(p.first), 0) << p.first;
    EXPECT_GE(wm.mannequins[0].model.findSegment(p.second), 0) << p.second;
  }
  EXPECT_FALSE(excluded("head", "foot_l"));
  EXPECT_FALSE(excluded("hand_l", "hand_r"));
}

TEST(WorldModel, RefusesBadSetupsNamingWhatAndWhere) {
  const auto one = [](bool controller) {
    std::vector<MannequinSetup> v;
    v.push_back(setup("worker", "", controller));
    return v;
  };
  SimConfig bad_step;
  bad_step.step = 0;
  EXPECT_NE(refusal(one(false), bad_step).find("step must be > 0"), std::string::npos);
  std::vector<MannequinSetup> twins = one(false);
  twins.push_back(setup("worker", "", false));
  EXPECT_NE(refusal(std::move(twins), SimConfig{}).find("two mannequins named 'worker'"), std::string::npos);
  std::vector<MannequinSetup> tail = one(false);
  tail[0].frames.push_back({"tail", "tail"});
  const std::string unknown = refusal(std::move(tail), SimConfig{});
  EXPECT_NE(unknown.find("mannequin 'worker'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("tail"), std::string::npos) << unknown;
  EXPECT_NE(refusal(one(false), physicsConfig()).find("mannequin 'worker': physics needs the controller stepper"), std::string::npos);
  SimConfig nan_gravity = physicsConfig();
  nan_gravity.physics.gravity.z() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refusal(one(true), nan_gravity).find("physics.gravity must be finite"), std::string::npos);
  SimConfig margin = physicsConfig();
  margin.physics.segment_margin = -0.01;
  EXPECT_NE(refusal(one(true), margin).find("physics.segment_margin"), std::string::npos);
  SimConfig balance = physicsConfig();
  balance.physics.balance_controller.enabled = true;
  balance.physics.balance_controller.frames = {"pelvis", "hand_r"};
  EXPECT_NE(refusal(one(true), balance).find("'hand_r' is not a driven frame of mannequin 'worker' (driven: pelvis, hand_l, head)"),
            std::string::npos);
  balance.physics.balance_controller.frames = {"head", "pelvis"};
  std::vector<MannequinSetup> ok = one(true);
  const WorldModel wm = buildWorldModel(std::move(ok), balance);
  EXPECT_EQ(wm.mannequins[0].balance_frames, (std::vector<int>{2, 0}));  // the config's order, as control-frame indices
}

TEST(WorldModel, AWorldBuiltFromItStepsAsOneBuiltFromTheSetups) {
  const auto setups = [] {
    std::vector<MannequinSetup> v;
    v.push_back(setup("a", "", true));
    return v;
  };
  const SimConfig config = physicsConfig();
  World direct(setups(), config);
  World from_model(buildWorldModel(setups(), config));
  // one Model per mannequin: the World's, the controller's and the model's are the same object
  const WorldModel& wm = from_model.worldModel();
  EXPECT_EQ(&from_model.model(0), &wm.mannequins[0].model);
  EXPECT_EQ(&static_cast<const ControllerStepper&>(from_model.stepper(0)).controller().model(), &wm.mannequins[0].model);
  // an actor standing where the standing mannequin's frames are, its hand moving up
  const skeleton::Model& model = direct.model(0);
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  for (int k = 0; k < 20; ++k) {
    mocap::Frame f;
    f.stamp_ns = k * 10'000'000LL;
    f.sequence = static_cast<std::uint64_t>(k + 1);
    for (const char* b : {"pelvis", "hand_l", "head"}) {
      math::SE3 T = d.oMf[static_cast<std::size_t>(model.frameIndex(b))];
      if (std::string(b) == "hand_l") T.p.z() += 0.01 * k;
      f.bodies.push_back({b, T, true});
    }
    for (World* w : {&direct, &from_model}) {
      w->addMocap(f);
      if (k == 0) w->anchor(0);
      for (int s = 0; s < 10; ++s) w->step();
    }
  }
  ASSERT_TRUE(direct.calibrated(0));
  EXPECT_EQ(direct.stepCount(), from_model.stepCount());
  EXPECT_EQ(direct.q(0), from_model.q(0));  // bit for bit
  EXPECT_EQ(direct.qdot(0), from_model.qdot(0));
  EXPECT_EQ(direct.contacts().size(), from_model.contacts().size());
  EXPECT_GT(direct.contacts().size(), 0u);  // it stands on the floor
}

}  // namespace world_model_test
