// BVH reader and forward kinematics: real captures, hand-computed poses, error reporting.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "mannequin/skeleton/bvh.hpp"
#include "bvh_data.hpp"

namespace sk = mannequin::skeleton;
using mannequin::math::Matrix3;
using mannequin::math::SE3;
using mannequin::math::Vector3;

namespace {

std::string dataPath(const std::string& name) { return mannequin::testing::bvhDataPath(name); }

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// two joints and an End Site; frame 0 turns the root 90° about z, frame 1 the child 90° about x
const char* kTiny =
    "HIERARCHY\n"
    "ROOT A\n"
    "{\n"
    "  OFFSET 1 2 3\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT B\n"
    "  {\n"
    "    OFFSET 0 1 0\n"
    "    CHANNELS 3 Xrotation Yrotation Zrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 0 2\n"
    "    }\n"
    "  }\n"
    "}\n"
    "MOTION\n"
    "Frames: 2\n"
    "Frame Time: 0.5\n"
    "10 0 0 90 0 0 0 0 0\n"
    "0 0 0 0 0 0 90 0 0\n";

Matrix3 rows(double a, double b, double c, double d, double e, double f, double g, double h, double i) {
  Matrix3 R;
  R << a, b, c, d, e, f, g, h, i;
  return R;
}

// a one-joint file with the given rotation channel order and values
std::string oneJoint(const std::string& order, const std::string& values) {
  return "HIERARCHY\nROOT J\n{\n OFFSET 0 0 0\n CHANNELS 3 " + order +
         "\n End Site\n {\n  OFFSET 1 0 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\n" + values + "\n";
}

}  // namespace

// ---- real captures -------------------------------------------------------------------------

TEST(BvhReal, CmuCapture) {
  const sk::Bvh bvh = sk::readBvhFile(dataPath("cmu_max_131_03.bvh"), {sk::bvhUnitScale(sk::BvhUnit::Cmu)});
  EXPECT_EQ(sk::bvhJointCount(bvh), 31);
  EXPECT_EQ(bvh.joints.size(), 38u);  // + 7 End Sites
  EXPECT_EQ(bvh.num_channels, 96);
  EXPECT_EQ(bvh.num_frames, 1102);
  EXPECT_DOUBLE_EQ(bvh.frame_time, 0.0083333);
  EXPECT_EQ(bvh.joints[0].name, "Hips");
  EXPECT_EQ(bvh.motion.size(), 1102u * 96u);
  // mixed rotation orders: legs ZYX, arms ZXY
  const int knee = sk::findBvhJoint(bvh, "LeftKnee");
  ASSERT_GE(knee, 0);
  EXPECT_EQ(bvh.joints[static_cast<std::size_t>(knee)].channels[1], sk::BvhChannel::Yrotation);
  const int shoulder = sk::findBvhJoint(bvh, "LeftShoulder");
  ASSERT_GE(shoulder, 0);
  EXPECT_EQ(bvh.joints[static_cast<std::size_t>(shoulder)].channels[1], sk::BvhChannel::Xrotation);
  EXPECT_DOUBLE_EQ(bvh.joints[static_cast<std::size_t>(knee)].offset.y(), -6.85026);
  // first and last values of the motion as written in the file
  EXPECT_DOUBLE_EQ(bvh.motion[0], 5.1723);
  EXPECT_DOUBLE_EQ(bvh.motion[1], 16.9371);
  EXPECT_DOUBLE_EQ(bvh.motion.back(), 13.7094);
  // the root's origin is offset + position channels, in metres when asked
  const auto file_units = sk::bvhWorldPoses(bvh, 0);
  EXPECT_TRUE(file_units[0].p.isApprox(Vector3(5.1723, 16.9371, -29.1264), 1e-15));
  const auto metres = sk::bvhWorldPoses(bvh, 0, sk::BvhLengthUnit::Metre);
  EXPECT_NEAR(metres[0].p.y(), 16.9371 * 0.056444, 1e-12);
  // a bone keeps its length in every frame: |p_knee - p_hip| = |offset of the knee|
  const int hip = sk::findBvhJoint(bvh, "LeftHip");
  const double bone = bvh.joints[static_cast<std::size_t>(knee)].offset.norm();
  for (const long long f : {0LL, 500LL, -1LL}) {
    const auto world = sk::bvhWorldPoses(bvh, f);
    EXPECT_NEAR((world[static_cast<std::size_t>(knee)].p - world[static_cast<std::size_t>(hip)].p).norm(), bone, 1e-9);
    for (const SE3& H : world) EXPECT_TRUE(mannequin::math::isRotation(H.R, 1e-12));
  }
}

TEST(BvhReal, MocapbankCapture) {
  const sk::Bvh bvh = sk::readBvhFile(dataPath("mocapbank_test.bvh"));
  EXPECT_EQ(sk::bvhJointCount(bvh), 19);
  EXPECT_EQ(bvh.num_channels, 60);
  EXPECT_EQ(bvh.num_frames, 455);
  EXPECT_DOUBLE_EQ(bvh.frame_time, 0.033333);
  EXPECT_EQ(bvh.joints[0].name, "Hips");
  EXPECT_DOUBLE_EQ(bvh.unit_scale_to_m, 0.01);  // default: centimetres
  EXPECT_DOUBLE_EQ(bvh.motion[0], -44.0003);
  EXPECT_DOUBLE_EQ(bvh.motion[2], 229.0256);
  // the Chest sits at offset (-0.1728, 10.2870, 0.1254) from the hips, rotated by the hips
  const auto world = sk::bvhWorldPoses(bvh, 0);
  const int chest = sk::findBvhJoint(bvh, "Chest");
  ASSERT_EQ(chest, 1);
  const Vector3 expected = world[0].p + world[0].R * Vector3(-0.1728, 10.2870, 0.1254);
  EXPECT_TRUE(world[1].p.isApprox(expected, 1e-14));
}

// ---- a converter's T-pose --------------------------------------------------------------------

// A stick figure 1.8 tall: head top at +0.9, feet at -0.9 (file units). Frame 0: both arms (0.7 long from
// shoulders 0.2 off the axis) spread horizontally, hand to hand 1.8: h/v = 1, a T-pose. Frame 1: the arms hang
// down (Zrotation -90 and +90): the horizontal extent is shoulder to shoulder, 0.4, h/v = 0.22.
const char* kStickFigure =
    "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    " JOINT Chest\n {\n  OFFSET 0 0.5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
    "  JOINT LArm\n  {\n   OFFSET 0.2 0.3 0\n   CHANNELS 1 Zrotation\n   End Site\n   {\n    OFFSET 0.7 0 0\n   }\n  }\n"
    "  JOINT RArm\n  {\n   OFFSET -0.2 0.3 0\n   CHANNELS 1 Zrotation\n   End Site\n   {\n    OFFSET -0.7 0 0\n   }\n  }\n"
    "  End Site\n  {\n   OFFSET 0 0.4 0\n  }\n }\n"
    " JOINT LLeg\n {\n  OFFSET 0.1 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 -0.9 0\n  }\n }\n"
    " JOINT RLeg\n {\n  OFFSET -0.1 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 -0.9 0\n  }\n }\n"
    "}\nMOTION\nFrames: 3\nFrame Time: 0.01\n"
    "0 0 0 0 0 0  0 0 0  0  0  0 0 0  0 0 0\n"
    "0 0 0 0 0 0  0 0 0  -90  90  0 0 0  0 0 0\n"
    "0 0 0 0 0 0  0 0 0  -90  90  0 0 0  0 0 0\n";

TEST(BvhTPose, SpreadArmsStandingUprightAreATPoseHangingArmsAreNot) {
  const sk::Bvh bvh = sk::parseBvh(kStickFigure, "stick");
  EXPECT_TRUE(sk::bvhIsTPose(bvh, 0));
  EXPECT_FALSE(sk::bvhIsTPose(bvh, 1));
  EXPECT_FALSE(sk::bvhIsTPose(bvh, -1));
  EXPECT_EQ(sk::bvhLeadingTPoseFrames(bvh, 0), 1);
  EXPECT_EQ(sk::bvhLeadingTPoseFrames(bvh, 1), 0);
  EXPECT_EQ(sk::bvhLeadingTPoseFrames(bvh, 3), 0);  // past the end: none
  EXPECT_EQ(sk::bvhTPoseFrames(bvh), std::vector<int>{0});
  EXPECT_THROW(sk::bvhIsTPose(bvh, 3), std::out_of_range);
  // the same spread arms with the whole figure tilted 60° (root Xrotation 60: the trunk leans, as in a stoop):
  // the horizontal extent stays large (h/v = 2) but the vertical extent is half the upright one of frames 1–2
  std::string tilted_text = kStickFigure;
  const std::string upright_frame0 = "0 0 0 0 0 0  0 0 0  0  0";
  tilted_text.replace(tilted_text.find(upright_frame0), upright_frame0.size(), "0 0 0 0 60 0  0 0 0  0  0");
  const sk::Bvh tilted = sk::parseBvh(tilted_text, "tilted");
  EXPECT_FALSE(sk::bvhIsTPose(tilted, 0));
  EXPECT_EQ(sk::bvhLeadingTPoseFrames(tilted, 0), 0);
}

TEST(BvhTPose, TheConvertersTPoseOfTheCmuBoxLiftsIsFoundAndNothingElse) {
  // cgspeed's MotionBuilder conversions add a T-pose as frame 0 (data/README.md); the stoop lift bends the trunk
  // horizontal with the arms down, which the upright test tells apart
  for (const char* name : {"cmu_115_02.bvh", "cmu_115_06.bvh"}) {
    const sk::Bvh bvh = sk::readBvhFile(dataPath(name));
    EXPECT_TRUE(sk::bvhIsTPose(bvh, 0)) << name;
    EXPECT_EQ(sk::bvhLeadingTPoseFrames(bvh, 0), 1) << name;
    EXPECT_EQ(sk::bvhTPoseFrames(bvh), std::vector<int>{0}) << name;
  }
  // captures without one
  for (const char* name : {"cmu_max_131_03.bvh", "mocapbank_test.bvh"})
    EXPECT_EQ(sk::bvhLeadingTPoseFrames(sk::readBvhFile(dataPath(name)), 0), 0) << name;
}

// ---- hand-computed forward kinematics -------------------------------------------------------

TEST(BvhKinematics, TinyHierarchyExact) {
  const sk::Bvh bvh = sk::parseBvh(kTiny, "tiny");
  ASSERT_EQ(bvh.joints.size(), 3u);
  EXPECT_EQ(sk::bvhJointCount(bvh), 2);
  EXPECT_EQ(bvh.num_channels, 9);
  EXPECT_EQ(bvh.joints[1].first_channel, 6);
  EXPECT_TRUE(bvh.joints[2].end_site);
  EXPECT_EQ(bvh.joints[2].parent, 1);

  // frame 0: root at offset + (10, 0, 0), turned 90° about z; the child follows
  auto w = sk::bvhWorldPoses(bvh, 0);
  const Matrix3 rz90 = rows(0, -1, 0, 1, 0, 0, 0, 0, 1);
  EXPECT_EQ(w[0].p, Vector3(11, 2, 3));
  EXPECT_EQ(w[0].R, rz90);
  EXPECT_EQ(w[1].p, Vector3(10, 2, 3));  // (11,2,3) + Rz90 (0,1,0)
  EXPECT_EQ(w[1].R, rz90);
  EXPECT_EQ(w[2].p, Vector3(10, 2, 5));  // + Rz90 (0,0,2)

  // frame 1 (also as -1): child turned 90° about x, so the End Site's +z offset points to -y
  w = sk::bvhWorldPoses(bvh, -1);
  const Matrix3 rx90 = rows(1, 0, 0, 0, 0, -1, 0, 1, 0);
  EXPECT_EQ(w[0].p, Vector3(1, 2, 3));
  EXPECT_EQ(w[0].R, Matrix3::Identity());
  EXPECT_EQ(w[1].p, Vector3(1, 3, 3));
  EXPECT_EQ(w[1].R, rx90);
  EXPECT_EQ(w[2].p, Vector3(1, 1, 3));

  // local pose and length scaling
  const SE3 local = sk::bvhLocalPose(bvh, 0, sk::bvhFrame(bvh, 0), 0.5);
  EXPECT_EQ(local.p, Vector3(5.5, 1, 1.5));
  const auto metres = sk::bvhWorldPoses(bvh, 0, sk::BvhLengthUnit::Metre);
  EXPECT_TRUE(metres[2].p.isApprox(Vector3(0.10, 0.02, 0.05), 1e-15));
}

TEST(BvhKinematics, ChannelOrderMatters) {
  // X = 90, Y = 90, Z = 0 written in two orders
  const sk::Bvh xyz = sk::parseBvh(oneJoint("Xrotation Yrotation Zrotation", "90 90 0"));
  const sk::Bvh zyx = sk::parseBvh(oneJoint("Zrotation Yrotation Xrotation", "0 90 90"));
  const auto a = sk::bvhWorldPoses(xyz, 0);
  const auto b = sk::bvhWorldPoses(zyx, 0);
  // Rx90 · Ry90 and Ry90 · Rx90, multiplied out by hand
  EXPECT_EQ(a[0].R, rows(0, 0, 1, 1, 0, 0, 0, 1, 0));
  EXPECT_EQ(b[0].R, rows(0, 1, 0, 0, 0, -1, -1, 0, 0));
  // so the End Site (offset +x) lands on +y in one case and -z in the other
  EXPECT_EQ(a[1].p, Vector3(0, 1, 0));
  EXPECT_EQ(b[1].p, Vector3(0, 0, -1));
}

TEST(BvhKinematics, EveryOrderMatchesAngleAxisProduct) {
  const char* names[3] = {"Xrotation", "Yrotation", "Zrotation"};
  const Vector3 axes[3] = {Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()};
  const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const double angles[3] = {31.5, -47.25, 123.0};  // degrees, in listed order
  for (const auto& o : orders) {
    const std::string order = std::string(names[o[0]]) + " " + names[o[1]] + " " + names[o[2]];
    const sk::Bvh bvh = sk::parseBvh(oneJoint(order, "31.5 -47.25 123"));
    const double d2r = std::numbers::pi / 180.0;
    const Matrix3 expected = (Eigen::AngleAxisd(angles[0] * d2r, axes[o[0]]) *
                              Eigen::AngleAxisd(angles[1] * d2r, axes[o[1]]) *
                              Eigen::AngleAxisd(angles[2] * d2r, axes[o[2]]))
                                 .toRotationMatrix();
    EXPECT_TRUE(sk::bvhWorldPoses(bvh, 0)[0].R.isApprox(expected, 1e-14)) << order;
  }
  // exact quarter turns, including negative and large multiples
  EXPECT_EQ(sk::bvhAxisRotation(2, -90), rows(0, 1, 0, -1, 0, 0, 0, 0, 1));
  EXPECT_EQ(sk::bvhAxisRotation(1, 450), rows(0, 0, 1, 0, 1, 0, -1, 0, 0));
  EXPECT_EQ(sk::bvhAxisRotation(0, 180), rows(1, 0, 0, 0, -1, 0, 0, 0, -1));
}

// ---- lexical variants ---------------------------------------------------------------------

TEST(BvhLexical, CrlfTabsAndShortNumbers) {
  const std::string messy =
      "\xEF\xBB\xBFHIERARCHY\r\n"
      "ROOT\tmixamorig:Hips  {\r\n"
      "\tOFFSET\t1 +2\t3.\r"  // lone CR ends a line too
      "\tCHANNELS 6 Xposition Yposition Zposition zrotation XROTATION Yrotation \r\n"
      "\tJOINT B\r\n\t{\r\n\t\tOFFSET .0 1 -.0\n\t\tCHANNELS 3 Xrotation Yrotation Zrotation\r\n"
      "\t\tEnd Site\r\n\t\t{ OFFSET 0 0 2e0 }\r\n\t}\r\n}\r\n"
      "MOTION\r\nFrames:\t2\r\nFrame Time:\t.5\r\n"
      "\r\n"  // blank line before the frames
      "10.0\t0 0 9e1 0 0 0 0 .0   \r\n"
      "  0 -0 0 0 0 0 +90 0 0\r\n\r\n\t\n";
  const sk::Bvh a = sk::parseBvh(kTiny);
  const sk::Bvh b = sk::parseBvh(messy);
  EXPECT_EQ(b.joints[0].name, "mixamorig:Hips");
  EXPECT_EQ(b.frame_time, 0.5);
  ASSERT_EQ(b.joints.size(), a.joints.size());
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    EXPECT_EQ(b.joints[j].offset, a.joints[j].offset) << j;
    EXPECT_EQ(b.joints[j].channels, a.joints[j].channels) << j;
  }
  EXPECT_EQ(b.motion, a.motion);
  EXPECT_EQ(sk::bvhWorldPoses(b, 1)[2].p, Vector3(1, 1, 3));
}

TEST(BvhLexical, DegenerateButLegal) {
  // zero frames, zero offsets, a root without channels, a joint name with spaces
  const sk::Bvh bvh = sk::parseBvh(
      "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 0\nJOINT Left Arm\n{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\n"
      "End Site\n{\nOFFSET 0 0 0\n}\n}\n}\nMOTION\nFrames: 0\nFrame Time: 0.04\n");
  EXPECT_EQ(bvh.num_frames, 0);
  EXPECT_EQ(bvh.num_channels, 1);
  EXPECT_TRUE(bvh.motion.empty());
  EXPECT_EQ(sk::findBvhJoint(bvh, "Left Arm"), 1);
  EXPECT_EQ(sk::findBvhJoint(bvh, "Right Arm"), -1);
  EXPECT_THROW(sk::resolveBvhFrame(bvh, 0), std::out_of_range);
  EXPECT_THROW(sk::bvhWorldPoses(bvh, -1), std::out_of_range);
}

TEST(BvhLexical, ResolveFrame) {
  const sk::Bvh bvh = sk::parseBvh(kTiny);
  EXPECT_EQ(sk::resolveBvhFrame(bvh, 0), 0);
  EXPECT_EQ(sk::resolveBvhFrame(bvh, 1), 1);
  EXPECT_EQ(sk::resolveBvhFrame(bvh, -1), 1);
  EXPECT_EQ(sk::resolveBvhFrame(bvh, -2), 0);
  EXPECT_THROW(sk::resolveBvhFrame(bvh, 2), std::out_of_range);
  EXPECT_THROW(sk::resolveBvhFrame(bvh, -3), std::out_of_range);
  EXPECT_THROW(sk::parseBvh(kTiny, "x", {0.0}), std::invalid_argument);
}

// ---- errors ---------------------------------------------------------------------------------

namespace {

struct ErrorCase {
  const char* what;
  std::string text;
  int line;
  const char* message;  // expected substring of message()
};

// kTiny with line `line` (1-based) replaced by `replacement` (may hold several lines or none)
std::string tinyWith(int line, const std::string& replacement) {
  std::istringstream in(kTiny);
  std::string out;
  std::string l;
  for (int n = 1; std::getline(in, l); ++n) out += (n == line ? replacement : l + "\n");
  return out;
}

}  // namespace

TEST(BvhErrors, EveryKindNamesItsLine) {
  const std::vector<ErrorCase> cases = {
      {"no HIERARCHY", "ROOT A\n", 1, "expected 'HIERARCHY', got 'ROOT'"},
      {"empty input", "", 1, "expected 'HIERARCHY', got end of file"},
      {"no ROOT", tinyWith(2, "JOINT A\n"), 2, "expected 'ROOT', got 'JOINT'"},
      {"no root name", tinyWith(2, "ROOT\n"), 2, "expected a joint name after 'ROOT'"},
      {"missing {", tinyWith(3, ""), 3, "expected '{', got 'OFFSET'"},
      {"bad offset", tinyWith(8, "OFFSET 0 one 0\n"), 8, "expected a number (OFFSET coordinate), got 'one'"},
      {"short offset", tinyWith(8, "OFFSET 0 1\n"), 9, "expected a number (OFFSET coordinate), got 'CHANNELS'"},
      {"nan offset", tinyWith(4, "OFFSET nan 2 3\n"), 4, "expected a finite number"},
      {"huge offset", tinyWith(4, "OFFSET 1e999 2 3\n"), 4, "expected a finite number"},
      {"no CHANNELS", tinyWith(9, ""), 9, "expected 'CHANNELS', got 'End'"},
      {"channel count", tinyWith(9, "CHANNELS 7 Xrotation\n"), 9, "expected a channel count from 0 to 6, got '7'"},
      {"unknown channel", tinyWith(9, "CHANNELS 3 Xrotation Wrotation Zrotation\n"), 9,
       "expected a channel name (Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation), got 'Wrotation'"},
      {"duplicate name", tinyWith(6, "JOINT A\n"), 6, "expected a unique joint name, got 'A' (already defined at line 2)"},
      {"channels in End Site", tinyWith(12, "OFFSET 0 0 2\nCHANNELS 0\n"), 13,
       "expected '}' closing the End Site, got 'CHANNELS'"},
      {"junk in joint", tinyWith(10, "Bone X\n"), 10, "expected 'JOINT', 'End Site' or '}', got 'Bone'"},
      {"missing }", tinyWith(15, ""), 15, "expected 'JOINT', 'End Site' or '}', got 'MOTION'"},
      {"EOF in hierarchy", "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\n", 6,
       "expected 'JOINT', 'End Site' or '}', got end of file"},
      {"no MOTION", tinyWith(16, "MOTON\n"), 16, "expected 'MOTION', got 'MOTON'"},
      {"negative frames", tinyWith(17, "Frames: -3\n"), 17, "expected a frame count >= 0, got '-3'"},
      {"bad frames", tinyWith(17, "Frames: two\n"), 17, "expected a frame count >= 0, got 'two'"},
      {"no Frames", tinyWith(17, "Frame: 2\n"), 17, "expected 'Frames:', got 'Frame:'"},
      {"zero frame time", tinyWith(18, "Frame Time: 0\n"), 18, "expected a frame time > 0 (seconds), got '0'"},
      {"negative frame time", tinyWith(18, "Frame Time: -0.1\n"), 18, "expected a frame time > 0 (seconds), got '-0.1'"},
      {"inf frame time", tinyWith(18, "Frame Time: inf\n"), 18, "expected a frame time > 0 (seconds), got 'inf'"},
      {"junk after time", tinyWith(18, "Frame Time: 0.5 s\n"), 18, "expected end of line after the frame time, got 's'"},
      {"short frame", tinyWith(19, "10 0 0 90 0 0 0 0\n"), 19, "expected 9 channel values in frame 0, got 8"},
      {"long frame", tinyWith(20, "0 0 0 0 0 0 90 0 0 0\n"), 20, "expected 9 channel values in frame 1, got 10"},
      {"bad value", tinyWith(20, "0 0 0 0 0 0 9O 0 0\n"), 20, "expected a number (channel 7 of frame 1), got '9O'"},
      {"nan value", tinyWith(19, "10 0 0 nan 0 0 0 0 0\n"), 19, "expected a finite number (channel 4 of frame 0), got 'nan'"},
      {"missing frame", tinyWith(20, ""), 20, "expected 2 frames (declared at line 17), found 1: unexpected end of file"},
      {"extra frame", tinyWith(20, "0 0 0 0 0 0 90 0 0\n1 2 3 4 5 6 7 8 9\n"), 21,
       "expected end of file after 2 frames (declared at line 17), got '1'"},
  };
  for (const ErrorCase& c : cases) {
    try {
      (void)sk::parseBvh(c.text, "case.bvh");
      ADD_FAILURE() << c.what << ": no error";
    } catch (const sk::BvhError& e) {
      EXPECT_EQ(e.file(), "case.bvh") << c.what;
      EXPECT_EQ(e.line(), c.line) << c.what << ": " << e.what();
      EXPECT_NE(e.message().find(c.message), std::string::npos) << c.what << ": " << e.what();
      EXPECT_EQ(std::string(e.what()), "case.bvh:" + std::to_string(c.line) + ": " + e.message()) << c.what;
    }
  }
}

TEST(BvhErrors, UnreadableFile) {
  try {
    (void)sk::readBvhFile("/nonexistent/dir/walk.bvh");
    ADD_FAILURE() << "no error";
  } catch (const sk::BvhError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/dir/walk.bvh");
    EXPECT_EQ(e.line(), 0);
    EXPECT_STREQ(e.what(), "/nonexistent/dir/walk.bvh: cannot open file");
  }
}

TEST(BvhErrors, ControlBytesAreEscapedInMessages) {
  try {
    (void)sk::parseBvh(std::string("HIER\x01\x7f", 6));
    ADD_FAILURE() << "no error";
  } catch (const sk::BvhError& e) {
    EXPECT_EQ(e.message(), "expected 'HIERARCHY', got 'HIER\\x01\\x7f'");
  }
}

TEST(BvhErrors, TruncatedRealFileNeverYieldsGarbage) {
  const std::string text = readText(dataPath("cmu_max_131_03.bvh"));
  const sk::Bvh full = sk::parseBvh(text, "full");
  ASSERT_EQ(full.num_frames, 1102);
  // the last frame line starts after the second-to-last line end
  const std::size_t last_line = text.rfind('\n', text.size() - 2) + 1;
  std::vector<std::size_t> cuts;
  for (std::size_t k = 0; k <= 200; ++k) cuts.push_back(text.size() * k / 200);
  for (std::size_t k = 1; k < 60; ++k) cuts.push_back(text.size() - k);  // inside the last frame line
  cuts.push_back(text.find("MOTION") + 3);
  cuts.push_back(text.find("Frame Time") + 6);
  int errors = 0;
  int parsed = 0;
  for (const std::size_t cut : cuts) {
    const std::string part = text.substr(0, cut);
    try {
      const sk::Bvh bvh = sk::parseBvh(part, "cut.bvh");
      // only a cut inside the last line's last number can still be a complete file
      ++parsed;
      EXPECT_GE(cut, last_line) << cut;
      ASSERT_EQ(bvh.num_frames, full.num_frames);
      ASSERT_EQ(bvh.motion.size(), full.motion.size());
      EXPECT_TRUE(std::equal(bvh.motion.begin(), bvh.motion.end() - 1, full.motion.begin())) << cut;
    } catch (const sk::BvhError& e) {
      ++errors;
      EXPECT_EQ(e.file(), "cut.bvh");
      EXPECT_GE(e.line(), 1);
      EXPECT_LE(e.line(), 1 + static_cast<int>(std::count(part.begin(), part.end(), '\n'))) << e.what();
    }
  }
  EXPECT_GT(errors, 200);
  EXPECT_GE(parsed, 2);  // the whole file, and cuts after the final line end or inside its last number
}
