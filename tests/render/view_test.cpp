// View files (configs/views/*.yaml): the shipped ones load, bad ones fail naming FILE:LINE and the key.
#include <gtest/gtest.h>

#include <filesystem>

#include "fixtures.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/v1/mocap.pb.h"

namespace mannequin::render {
namespace {

std::string errorOf(const std::string& yaml) {
  try {
    (void)parseView(yaml, "v.yaml");
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ViewConfig, ShippedViewsLoadAndTheCaveWallsShareTheirEdges) {
  const ViewConfig d = loadView(testing::sourcePath("configs/views/desktop.yaml"));
  EXPECT_EQ(d.type, ViewConfig::Type::kDesktop);
  EXPECT_EQ(d.width, 1280);
  EXPECT_NEAR(d.orbit.distance, 3.6, 1e-12);
  const ViewConfig f = loadView(testing::sourcePath("configs/views/wall_front.yaml"));
  const ViewConfig l = loadView(testing::sourcePath("configs/views/wall_left.yaml"));
  const ViewConfig r = loadView(testing::sourcePath("configs/views/wall_right.yaml"));
  for (const ViewConfig* v : {&f, &l, &r}) EXPECT_EQ(v->type, ViewConfig::Type::kWall) << v->name;
  EXPECT_LT((f.wall.lower_right - r.wall.lower_left).norm(), 1e-12);
  EXPECT_LT((f.wall.lower_left - l.wall.lower_right).norm(), 1e-12);
  // every shipped view file parses
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::sourcePath("configs/views"))) {
    EXPECT_NO_THROW((void)loadView(e.path().string())) << e.path();
    ++n;
  }
  EXPECT_GE(n, 4);
}

TEST(ViewConfig, ErrorsNameFileLineAndKey) {
  {
    const std::string e = errorOf("name: x\ntype: desktop\ncamera: {distanse: 3}\n");
    EXPECT_NE(e.find("v.yaml:3"), std::string::npos) << e;
    EXPECT_NE(e.find("distanse"), std::string::npos) << e;
  }
  EXPECT_NE(errorOf("name: x\n").find("type"), std::string::npos);
  EXPECT_NE(errorOf("type: orbit\n").find("desktop"), std::string::npos);
  EXPECT_NE(errorOf("type: desktop\ncamera: {distance: -1}\n").find("camera.distance"), std::string::npos);
  EXPECT_NE(errorOf("type: desktop\nsize: [0, 10]\n").find("size"), std::string::npos);
  EXPECT_NE(errorOf("type: wall\nhead: [0, 0, 1]\n").find("wall"), std::string::npos);
  {  // skewed wall: the error names the wall key and says why
    const std::string e = errorOf(
        "type: wall\nwall: {lower_left: [1, 1, 0], lower_right: [1, -1, 0], upper_left: [1, 0.5, 1]}\n");
    EXPECT_NE(e.find("v.yaml:2"), std::string::npos) << e;
    EXPECT_NE(e.find("orthogonal"), std::string::npos) << e;
  }
  {  // head behind the screen
    const std::string e = errorOf(
        "type: wall\nwall: {lower_left: [1, 1, 0], lower_right: [1, -1, 0], upper_left: [1, 1, 2]}\nhead: [2, 0, 1]\n");
    EXPECT_NE(e.find("behind"), std::string::npos) << e;
  }
  EXPECT_NE(errorOf("type: desktop\nwall: {}\n").find("wall"), std::string::npos);
  // a missing file names the file
  try {
    (void)loadView("/nonexistent/view.yaml");
    FAIL() << "no error";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/view.yaml"), std::string::npos) << e.what();
  }
}

TEST(ViewConfig, TrackedHeadIsTheHeadBodysPoseTimesTheOffset) {
  const ViewConfig v = parseView(
      "type: wall\nwall: {lower_left: [1.5, 1.5, 0], lower_right: [1.5, -1.5, 0], upper_left: [1.5, 1.5, 3]}\n"
      "head_body: head\nhead_offset: [0.1, 0, 0.05]\n",
      "v.yaml");
  EXPECT_EQ(v.head_body, "head");
  v1::MocapFrame f;
  v1::RigidBody* other = f.add_bodies();
  other->set_name("hand_l");
  other->set_tracked(true);
  EXPECT_FALSE(trackedHead(f, v).has_value());  // no head body in the frame
  v1::RigidBody* h = f.add_bodies();
  h->set_name("head");
  h->set_tracked(false);
  h->mutable_pose()->mutable_position()->set_z(1.6);
  EXPECT_FALSE(trackedHead(f, v).has_value());  // occluded: keep the previous head
  h->set_tracked(true);
  // rotated 90° about z: the body's x offset becomes +y in the room
  const double c = std::sqrt(0.5);
  h->mutable_pose()->mutable_orientation()->set_w(c);
  h->mutable_pose()->mutable_orientation()->set_z(c);
  h->mutable_pose()->mutable_position()->set_x(0.2);
  const auto eye = trackedHead(f, v);
  ASSERT_TRUE(eye.has_value());
  EXPECT_LT((*eye - Vec3(0.2, 0.1, 1.65)).norm(), 1e-12);
  // a desktop view has no head
  EXPECT_NE(errorOf("type: desktop\nhead_body: head\n").find("head_body"), std::string::npos);
  ViewConfig d;
  EXPECT_FALSE(trackedHead(f, d).has_value());
}

}  // namespace
}  // namespace mannequin::render

namespace mannequin::render {
namespace {

TEST(ViewConfig, SyncAndItsTimeout) {
  const ViewConfig off = parseView("type: desktop\n", "v.yaml");
  EXPECT_FALSE(off.sync);
  EXPECT_DOUBLE_EQ(off.sync_timeout, 0.5);
  const ViewConfig on = parseView("type: desktop\nsync: true\nsync_timeout: 0.25\n", "v.yaml");
  EXPECT_TRUE(on.sync);
  EXPECT_DOUBLE_EQ(on.sync_timeout, 0.25);
  const std::string bad = errorOf("type: desktop\nsync: true\nsync_timeout: 0\n");
  EXPECT_NE(bad.find("v.yaml:3"), std::string::npos) << bad;
  EXPECT_NE(bad.find("sync_timeout"), std::string::npos) << bad;
  EXPECT_NE(errorOf("type: desktop\nsync: maybe\n").find("v.yaml:2"), std::string::npos);
}

}  // namespace
}  // namespace mannequin::render

namespace mannequin::render {
namespace {

TEST(ViewConfig, LayersAndTheirErrors) {
  const ViewConfig def = parseView("type: desktop\n", "v.yaml");
  for (int i = 0; i + 1 < RenderLayers::kCount; ++i) EXPECT_TRUE(def.layers.flag(i)) << RenderLayers::names()[static_cast<std::size_t>(i)];
  EXPECT_FALSE(def.layers.overlay);
  const ViewConfig v = parseView("type: desktop\nlayers:\n  mannequins: false\n  control_frames: false\n  overlay: true\n", "v.yaml");
  EXPECT_FALSE(v.layers.mannequins);
  EXPECT_FALSE(v.layers.control_frames);
  EXPECT_TRUE(v.layers.overlay);
  EXPECT_TRUE(v.layers.scene);
  EXPECT_FALSE(v.layers.shows(Layer::kMannequin));
  EXPECT_FALSE(v.layers.shows(Layer::kControl));
  EXPECT_TRUE(v.layers.shows(Layer::kForce));
  const std::string unknown = errorOf("type: desktop\nlayers:\n  mannequins: true\n  forces: false\n");
  EXPECT_NE(unknown.find("v.yaml:4"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("forces"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("control_frames"), std::string::npos) << unknown;  // the list of valid keys
  EXPECT_NE(errorOf("type: desktop\nlayers: {scene: perhaps}\n").find("v.yaml:2"), std::string::npos);
  EXPECT_NE(errorOf("type: desktop\nlayers: [scene]\n").find("layers"), std::string::npos);
}

TEST(ViewConfig, FollowIsADesktopKeyNamingAMannequinByNameOrIndex) {
  EXPECT_EQ(parseView("type: desktop\nfollow: operator\n", "v.yaml").follow, "operator");
  EXPECT_EQ(parseView("type: desktop\n", "v.yaml").follow, "");
  const std::string wall = errorOf(
      "type: wall\nwall: {lower_left: [1, 1, 0], lower_right: [1, -1, 0], upper_left: [1, 1, 2]}\nfollow: 0\n");
  EXPECT_NE(wall.find("v.yaml:3"), std::string::npos) << wall;
  EXPECT_NE(wall.find("desktop"), std::string::npos) << wall;
  EXPECT_NE(errorOf("type: desktop\nfollow: ''\n").find("follow"), std::string::npos);

  v1::WorldState ws;
  for (const char* name : {"alice", "bob"}) {
    v1::MannequinState* m = ws.add_mannequins();
    m->set_name(name);
    for (const char* seg : {"foot_l", "pelvis"}) {
      v1::NamedPose* s = m->add_segments();
      s->set_name(seg);
      testing::toMsg(Vector3(m->name() == "bob" ? 2.0 : -1.0, std::string(seg) == "pelvis" ? 0.5 : 0.7, 1.0),
                     *s->mutable_pose()->mutable_position());
    }
  }
  ASSERT_TRUE(followPoint(ws, "bob"));
  EXPECT_TRUE(followPoint(ws, "bob")->isApprox(Vec3(2.0, 0.5, 1.0)));  // the pelvis, not the first segment
  EXPECT_TRUE(followPoint(ws, "0")->isApprox(Vec3(-1.0, 0.5, 1.0)));   // by index
  EXPECT_FALSE(followPoint(ws, "2"));
  EXPECT_FALSE(followPoint(ws, "carol"));
  EXPECT_FALSE(followPoint(ws, ""));
  OrbitCamera orbit;
  orbit.target = Vec3(0.4, 0.0, 0.9);
  const OrbitCamera f = followed(orbit, ws, "bob", Eigen::Vector2d(0.1, -0.2));
  EXPECT_TRUE(f.target.isApprox(Vec3(2.1, 0.3, 0.9)));  // horizontal only: the height stays the view's
  EXPECT_TRUE(followed(orbit, ws, "carol").target.isApprox(orbit.target));
}

}  // namespace
}  // namespace mannequin::render

namespace mannequin::render {
namespace {

const char* kStereoWall =
    "type: wall\nwall: {lower_left: [1.5, 1.5, 0], lower_right: [1.5, -1.5, 0], upper_left: [1.5, 1.5, 3]}\n"
    "head: [0, 0.1, 1.7]\n";

TEST(ViewConfig, StereoWallHasTwoEyesAlongTheWallsRightAxis) {
  const ViewConfig mono = parseView(kStereoWall, "v.yaml");
  EXPECT_FALSE(mono.stereo.enabled);
  ASSERT_EQ(mono.eyes(640, 320).size(), 1u);
  EXPECT_TRUE(mono.eyes(640, 320)[0].camera.eye.isApprox(mono.head));
  EXPECT_EQ(mono.eyes(640, 320)[0].width, 640);
  const ViewConfig v = parseView(std::string(kStereoWall) + "stereo: {eye_separation: 0.07, mode: side_by_side}\n", "v.yaml");
  ASSERT_TRUE(v.stereo.enabled);
  EXPECT_DOUBLE_EQ(v.stereo.eye_separation, 0.07);
  const auto eyes = v.eyes(641, 320);
  ASSERT_EQ(eyes.size(), 2u);
  // the wall's right axis is −y (lower_left → lower_right): the left eye is at +y
  EXPECT_TRUE(eyes[0].camera.eye.isApprox(v.head + Vec3(0, 0.035, 0), 1e-12));
  EXPECT_TRUE(eyes[1].camera.eye.isApprox(v.head - Vec3(0, 0.035, 0), 1e-12));
  EXPECT_EQ(eyes[0].x, 0);
  EXPECT_EQ(eyes[0].width, 320);
  EXPECT_EQ(eyes[1].x, 320);
  EXPECT_EQ(eyes[1].width, 321);
  // each eye's frustum still maps the wall's corners onto its half's corners
  for (const EyeView& e : eyes) {
    const Eigen::Vector2d ll = e.camera.pixel(v.wall.lower_left, e.width, 320);
    EXPECT_NEAR(ll.x(), 0.0, 1e-9);
    EXPECT_NEAR(ll.y(), 320.0, 1e-9);
    EXPECT_NEAR(e.camera.pixel(v.wall.lower_right, e.width, 320).x(), e.width, 1e-9);
  }
  // errors: FILE:LINE and key
  const auto err = [](const std::string& extra) { return errorOf(std::string(kStereoWall) + extra); };
  EXPECT_NE(err("stereo: {eye_separation: 0.07, mode: anaglyph}\n").find("v.yaml:4"), std::string::npos);
  EXPECT_NE(err("stereo: {eye_separation: 0.07, mode: anaglyph}\n").find("side_by_side"), std::string::npos);
  EXPECT_NE(err("stereo: {eye_sep: 0.07}\n").find("eye_sep"), std::string::npos);
  EXPECT_NE(err("stereo: {eye_separation: -0.07}\n").find("stereo.eye_separation"), std::string::npos);
  EXPECT_NE(err("stereo: {eye_separation: 2}\n").find("(0, 0.5]"), std::string::npos);
  const std::string desk = errorOf("type: desktop\nstereo: {eye_separation: 0.065}\n");
  EXPECT_NE(desk.find("v.yaml:2"), std::string::npos) << desk;
  EXPECT_NE(desk.find("wall"), std::string::npos) << desk;
}

}  // namespace
}  // namespace mannequin::render
