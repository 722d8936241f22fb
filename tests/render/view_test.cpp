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
