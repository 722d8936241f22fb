#include "mannequin/skeleton/model.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace mannequin::skeleton;

namespace {
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Model, IndicesAndSizesFollowJointTypes) {
  Model m;
  m.name = "t";
  const int root = m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  const int ball = m.addJoint("ball", JointType::kBall, root, SE3::Identity());
  const int rev = m.addJoint("rev", JointType::kRevolute, ball, SE3::Identity(), Vector3(0, 0, 2));
  EXPECT_EQ(m.nq, 10);
  EXPECT_EQ(m.nv, 10);
  EXPECT_EQ(m.joints[ball].idx_q, 6);
  EXPECT_EQ(m.joints[rev].idx_v, 9);
  EXPECT_TRUE(m.joints[rev].axis.isApprox(Vector3::UnitZ()));  // normalised
  EXPECT_EQ(m.support[rev], (std::vector<int>{root, ball, rev}));
  EXPECT_EQ(m.coordinateNames()[6], "ball.x");
  EXPECT_EQ(m.coordinateNames()[9], "rev");
  EXPECT_TRUE(std::isinf(m.lower_limit(9)));
  m.setLimits(9, -1, 1);
  EXPECT_EQ(m.upper_limit(9), 1);
}

TEST(Model, BadConstructionGivesClearErrors) {
  Model m;
  m.name = "t";
  m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  EXPECT_NE(errorOf([&] { m.addJoint("root", JointType::kBall, 0, SE3::Identity()); }).find("defined twice"), std::string::npos);
  EXPECT_NE(errorOf([&] { m.addJoint("x", JointType::kBall, 5, SE3::Identity()); }).find("parent index 5"), std::string::npos);
  EXPECT_NE(errorOf([&] { m.addJoint("x", JointType::kRevolute, 0, SE3::Identity(), Vector3::Zero()); }).find("axis"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { m.addJoint("ff", JointType::kFreeFlyer, 0, SE3::Identity()); }).find("free flyer"),
            std::string::npos);
  SE3 bad;
  bad.p.x() = std::nan("");
  EXPECT_NE(errorOf([&] { m.addJoint("x", JointType::kBall, 0, bad); }).find("not a finite"), std::string::npos);
  Segment s;
  s.name = "s";
  s.joint = 0;
  s.mass = -1;
  EXPECT_NE(errorOf([&] { m.addSegment(s); }).find("mass"), std::string::npos);
  EXPECT_NE(errorOf([&] { m.setLimits(0, 1, -1); }).find("not an interval"), std::string::npos);
  EXPECT_NE(errorOf([&] { m.setLimits(0, std::nan(""), 1); }).find("not an interval"), std::string::npos);
  // unknown names list what exists
  const std::string msg = errorOf([&] { m.jointIndex("elbow"); });
  EXPECT_NE(msg.find("unknown joint 'elbow'"), std::string::npos);
  EXPECT_NE(msg.find("root"), std::string::npos);
  EXPECT_EQ(m.findFrame("nope"), -1);
}

TEST(Model, DataIsSizedFromModel) {
  Model m;
  m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  m.addJoint("a", JointType::kBall, 0, SE3::Identity());
  m.addFrame("f", 1, SE3::Identity());
  Data d(m);
  EXPECT_EQ(d.oMi.size(), 2u);
  EXPECT_EQ(d.oMf.size(), 1u);
  EXPECT_EQ(d.J.cols(), 9);
  EXPECT_EQ(d.Jcom.cols(), 9);
}
