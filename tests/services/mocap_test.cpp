// Capture sources: the DTrack2 ASCII parser on real-format datagrams and over loopback UDP, the BVH
// source against the BVH forward kinematics, synthetic trajectories, configs.
#include <gtest/gtest.h>

#include <asio.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "mannequin/core/paths.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/mocap/bvh_source.hpp"
#include "mannequin/mocap/dtrack2.hpp"
#include "mannequin/mocap/synthetic_source.hpp"
#include "mannequin/skeleton/bvh.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/validate.hpp"

using namespace mannequin;
using namespace mannequin::mocap;

namespace {
v1::MocapFrame wire(const Frame& f, const std::string& kind) {
  v1::MocapFrame m;
  transport::toMsg(f, kind, m);
  return m;
}
}  // namespace

namespace {
// A datagram as ART DTrack2 sends it (one body, id 45), CR LF line ends.
const std::string kRealDatagram =
    "fr 518169\r\nts 30331.359222\r\n6dcal 2\r\n"
    "6d 1 [45 1.000][-5.026 695.186 763.716 -7.7879 -10.9331 -3.3467]"
    "[0.980175 -0.032183 0.195503 0.057318 0.990587 -0.124306 -0.189662 0.133047 0.972793]\r\n";

math::Matrix3 rx(double d) { return math::expSO3(math::Vector3(d * M_PI / 180, 0, 0)); }
math::Matrix3 ry(double d) { return math::expSO3(math::Vector3(0, d * M_PI / 180, 0)); }
math::Matrix3 rz(double d) { return math::expSO3(math::Vector3(0, 0, d * M_PI / 180)); }

core::ConfigNode configOf(const std::string& text) { return core::ConfigNode::parse(text, "test.yaml"); }
}  // namespace

TEST(DTrack2, ParsesARealDatagram) {
  DTrackDatagram f;
  ASSERT_EQ(parseDTrack(kRealDatagram, f), "");
  EXPECT_EQ(f.frame_counter.value(), 518169u);
  EXPECT_DOUBLE_EQ(f.timestamp.value(), 30331.359222);
  EXPECT_EQ(f.calibrated_bodies.value(), 2);
  ASSERT_EQ(f.bodies.size(), 1u);
  const DTrackBody& b = f.bodies[0];
  EXPECT_EQ(b.id, 45);
  EXPECT_EQ(b.quality, 1.0);
  EXPECT_EQ(b.position_mm, math::Vector3(-5.026, 695.186, 763.716));
  // b0..b8 are column-wise, and the matrix is the one of the angles on the same line, R = Rx(η) Ry(θ) Rz(φ)
  EXPECT_DOUBLE_EQ(b.rotation(0, 1), 0.057318);
  EXPECT_DOUBLE_EQ(b.rotation(1, 0), -0.032183);
  EXPECT_LT((b.rotation - rx(-7.7879) * ry(-10.9331) * rz(-3.3467)).norm(), 1e-5);
}

TEST(DTrack2, AcceptsLfLinesThreeValuePositionsAndSkipsOtherRecords) {
  DTrackDatagram f;
  const std::string d =
      "fr 7\n6df2 1 1 [0 1.000 2 2][1 2 3][1 0 0 0 1 0 0 0 1][0 0.0 0.0]\n"
      "6d 2 [0 0.5][100 200 300][1 0 0 0 1 0 0 0 1] [3 -1.000][0 0 0][1 0 0 0 1 0 0 0 1]\n3d 0\n";
  ASSERT_EQ(parseDTrack(d, f), "");
  ASSERT_EQ(f.bodies.size(), 2u);
  EXPECT_EQ(f.bodies[0].position_mm, math::Vector3(100, 200, 300));
  EXPECT_EQ(f.bodies[1].id, 3);
  EXPECT_EQ(f.bodies[1].quality, -1.0);
  EXPECT_FALSE(f.timestamp.has_value());
}

TEST(DTrack2, RejectsMalformedDatagramsNamingTheLine) {
  const std::string I = "[1 0 0 0 1 0 0 0 1]";
  struct Case {
    std::string text, expect;
  } cases[] = {
      {"ts 1.0\n6d 0\n", "no 'fr' line"},
      {"fr x\n", "line 1: fr"},
      {"fr 1\nts nan\n", "line 2: ts"},
      {"fr 1\n6d 2 [0 1.0][0 0 0]" + I + "\n", "line 2: 6d body 1"},      // count says 2, one body
      {"fr 1\n6d 1 [0 1.0][0 0]" + I + "\n", "line 2: 6d body 0"},        // two position values
      {"fr 1\n6d 1 [0 1.0][0 0 0][1 0 0 0 1 0 0 0]\n", "line 2"},        // 8 matrix values
      {"fr 1\n6d 1 [0 1.0][0 0 0][2 0 0 0 1 0 0 0 1]\n", "not a rotation"},
      {"fr 1\n6d 1 [0 1.0][0 nan 0]" + I + "\n", "non-finite"},
      {"fr 1\n6d 2 [4 1.0][0 0 0]" + I + "[4 1.0][0 0 0]" + I + "\n", "duplicate id 4"},
      {"fr 1\n6d 1 [-2 1.0][0 0 0]" + I + "\n", "bad id"},
      {"fr 1\n6d 1 [0 1.0][0 0 0]" + I + " junk\n", "unexpected text"},
      {std::string("fr 1\n6d 0\x01\n"), "control character"},
  };
  for (const auto& c : cases) {
    DTrackDatagram f;
    const std::string why = parseDTrack(c.text, f);
    EXPECT_NE(why.find(c.expect), std::string::npos) << "datagram: " << c.text << "\nerror: " << why;
  }
}

TEST(DTrack2, LoopbackUdpDatagramsBecomeFrames) {
  DTrackOptions o;
  o.port = 0;  // ephemeral
  o.bodies = {{45, "head"}, {3, "hand_l"}};
  DTrackSource source(o);
  ASSERT_GT(source.port(), 0);
  asio::io_context io;
  asio::ip::udp::socket tx(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
  const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(source.port()));
  tx.send_to(asio::buffer(std::string("garbage that is not DTrack\r\n")), to);
  tx.send_to(asio::buffer(kRealDatagram), to);
  std::optional<Frame> s;
  for (int k = 0; k < 100 && !s; ++k) s = source.next(std::chrono::milliseconds(20));
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(source.malformedDatagrams(), 1u);
  EXPECT_EQ(s->frame_number, 518169u);
  EXPECT_EQ(s->stamp_ns, 30331359222000LL);
  ASSERT_EQ(s->bodies.size(), 2u);
  EXPECT_EQ(s->bodies[0].name, "head");
  EXPECT_TRUE(s->bodies[0].tracked);
  EXPECT_LT((s->bodies[0].pose.p - math::Vector3(-0.005026, 0.695186, 0.763716)).norm(), 1e-12);  // mm → m
  EXPECT_EQ(s->bodies[1].name, "hand_l");
  EXPECT_FALSE(s->bodies[1].tracked);  // not in the datagram
  EXPECT_EQ(transport::validateMocapFrame(wire(*s, "dtrack2")), "");
  // next frame: head lost (quality −1), hand seen; the head keeps its last pose, untracked
  tx.send_to(asio::buffer(std::string("fr 518170\r\n6d 2 [45 -1.000][0 0 0][1 0 0 0 1 0 0 0 1]"
                                      "[3 0.800][10 20 30][0 1 0 -1 0 0 0 0 1]\r\n")),
             to);
  s.reset();
  for (int k = 0; k < 100 && !s; ++k) s = source.next(std::chrono::milliseconds(20));
  ASSERT_TRUE(s.has_value());
  EXPECT_FALSE(s->bodies[0].tracked);
  EXPECT_LT((s->bodies[0].pose.p - math::Vector3(-0.005026, 0.695186, 0.763716)).norm(), 1e-12);
  EXPECT_TRUE(s->bodies[1].tracked);
  EXPECT_DOUBLE_EQ(s->bodies[1].quality, 0.8);
  EXPECT_LT((s->bodies[1].pose.R - rz(90)).norm(), 1e-12);  // columns (0,1,0), (−1,0,0), (0,0,1)
  EXPECT_FALSE(source.next(std::chrono::milliseconds(0)).has_value());
}

TEST(BvhSource, PublishesTheForwardKinematicsInTheRoomFrame) {
  BvhSourceOptions o;
  o.file = "data/bvh/cmu_max_131_03.bvh";
  o.unit_scale_to_m = skeleton::bvhUnitScale(skeleton::BvhUnit::Cmu);
  o.bodies = {{"pelvis", "Hips"}, {"hand_l", "LeftWrist"}};
  o.paced = false;
  o.start_frame = 10;
  o.end_frame = 12;
  o.loop = true;
  BvhSource src(o);
  skeleton::BvhReadOptions ro;
  ro.unit_scale_to_m = o.unit_scale_to_m;
  const skeleton::Bvh bvh = skeleton::readBvhFile(o.file, ro);
  const auto world11 = skeleton::bvhWorldPoses(bvh, 11, skeleton::BvhLengthUnit::Metre);
  const int wrist = skeleton::findBvhJoint(bvh, "LeftWrist");
  std::vector<Frame> got;
  for (int k = 0; k < 7; ++k) got.push_back(*src.next(std::chrono::milliseconds(0)));
  EXPECT_TRUE(got[0].calibration_pose);
  EXPECT_FALSE(got[1].calibration_pose);
  // frames 10, 11, 12, 10, 11, 12, 10 with increasing numbers and capture times
  for (int k = 0; k < 7; ++k) {
    EXPECT_EQ(got[k].frame_number, static_cast<unsigned>(k));
    EXPECT_EQ(got[k].stamp_ns, std::llround(k * bvh.frame_time * 1e9));
  }
  const math::Vector3 p = world11[wrist].p;
  const math::Vector3 expected(p.z(), p.x(), p.y());  // x_room = z_bvh, y_room = x_bvh, z_room = y_bvh
  EXPECT_LT((got[1].bodies[1].pose.p - expected).norm(), 1e-12);
  EXPECT_LT((got[4].bodies[1].pose.p - expected).norm(), 1e-12);
  EXPECT_EQ(got[1].bodies[1].name, "hand_l");
  EXPECT_TRUE(got[1].bodies[1].tracked);
  // the room frame is z up: the pelvis of a standing actor is about 1 m above the floor
  EXPECT_GT(got[0].bodies[0].pose.p.z(), 0.8);
  EXPECT_LT(got[0].bodies[0].pose.p.z(), 1.2);
  EXPECT_FALSE(src.finished());
}

TEST(BvhSource, SkipsTheConvertersTPoseSoThatTheCalibrationTakesTheCapturesFirstFrame) {
  BvhSourceOptions o;
  o.file = "data/bvh/cmu_115_02.bvh";
  o.unit_scale_to_m = skeleton::bvhUnitScale(skeleton::BvhUnit::Cmu);
  o.bodies = {{"hand_l", "LeftHand"}, {"pelvis", "Hips"}};
  o.paced = false;
  BvhSource src(o);
  EXPECT_EQ(src.skippedTPoseFrames(), 1);
  EXPECT_EQ(src.firstFrame(), 1);
  EXPECT_NE(src.describe().find("after 1 T-pose frame"), std::string::npos) << src.describe();
  const Frame first = *src.next(std::chrono::milliseconds(0));
  EXPECT_TRUE(first.calibration_pose);
  EXPECT_EQ(first.frame_number, 0u);
  EXPECT_EQ(first.stamp_ns, 0);
  // it is file frame 1: the actor's hand hangs well below the pelvis (in the T-pose it is at shoulder height)
  const auto world1 = skeleton::bvhWorldPoses(src.bvh(), 1, skeleton::BvhLengthUnit::Metre);
  const math::Vector3 p = world1[static_cast<std::size_t>(skeleton::findBvhJoint(src.bvh(), "LeftHand"))].p;
  EXPECT_LT((first.bodies[0].pose.p - math::Vector3(p.z(), p.x(), p.y())).norm(), 1e-12);
  EXPECT_LT(first.bodies[0].pose.p.z(), first.bodies[1].pose.p.z());
  // skip_tpose: false plays the file from frame 0, T-pose included
  o.skip_tpose = false;
  BvhSource raw(o);
  EXPECT_EQ(raw.skippedTPoseFrames(), 0);
  const Frame tpose = *raw.next(std::chrono::milliseconds(0));
  EXPECT_GT(tpose.bodies[0].pose.p.z(), tpose.bodies[1].pose.p.z() + 0.2);  // the hand above the pelvis
  // a range made of T-poses only is refused, naming the file
  o.skip_tpose = true;
  o.end_frame = 0;
  try {
    BvhSource none(o);
    ADD_FAILURE() << "a T-pose-only range was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cmu_115_02.bvh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("T-pose"), std::string::npos) << e.what();
  }
}

TEST(BvhSource, EndsWithoutLoopAndRejectsBadRanges) {
  BvhSourceOptions o;
  o.file = "data/bvh/cmu_max_131_03.bvh";
  o.bodies = {{"pelvis", "Hips"}};
  o.paced = false;
  o.start_frame = -2;
  BvhSource src(o);
  EXPECT_TRUE(src.next(std::chrono::milliseconds(0)).has_value());
  EXPECT_TRUE(src.next(std::chrono::milliseconds(0)).has_value());
  EXPECT_FALSE(src.next(std::chrono::milliseconds(0)).has_value());
  EXPECT_TRUE(src.finished());
  o.start_frame = 5000;
  EXPECT_THROW(BvhSource{o}, std::invalid_argument);
  o.start_frame = 10;
  o.end_frame = 5;
  EXPECT_THROW(BvhSource{o}, std::invalid_argument);
  o.end_frame = -1;
  o.bodies = {{"pelvis", "NoSuchJoint"}};
  EXPECT_THROW(BvhSource{o}, std::invalid_argument);
}

TEST(Synthetic, HandCheckablePositionsAndOcclusion) {
  SyntheticOptions o;
  o.rate_hz = 100;
  o.paced = false;
  o.duration = 1.0;
  SyntheticBody b;
  b.name = "hand_l";
  b.center = {1, 2, 3};
  b.amplitude = {0.5, 0, -0.2};
  b.frequency = 0.25;  // sin = 1 at t = 1 s
  o.bodies = {b};
  o.occlusions = {{"hand_l", 0.5, 0.6}};
  SyntheticSource src(o);
  const Frame s100 = src.frameAt(100);
  EXPECT_LT((s100.bodies[0].pose.p - math::Vector3(1.5, 2, 2.8)).norm(), 1e-12);
  EXPECT_EQ(s100.stamp_ns, 1000000000);
  EXPECT_TRUE(src.frameAt(49).bodies[0].tracked);
  EXPECT_FALSE(src.frameAt(50).bodies[0].tracked);
  EXPECT_FALSE(src.frameAt(59).bodies[0].tracked);
  EXPECT_TRUE(src.frameAt(60).bodies[0].tracked);
  int n = 0;
  while (src.next(std::chrono::milliseconds(0))) ++n;
  EXPECT_EQ(n, 101);  // t = 0 .. 1 s inclusive
  EXPECT_TRUE(src.finished());
}

// Waypoints: rest at each, the minimum-jerk law between (s(½) = ½, s(¼) = 10/64 − 15/256 + 6/1024) for the
// position and the orientation, the first held before it and the last after it.
TEST(Synthetic, WaypointsAreJoinedByMinimumJerkSegmentsAndHeldAtTheEnds) {
  SyntheticOptions o;
  o.rate_hz = 100;
  o.paced = false;
  o.duration = 4.0;
  SyntheticBody b;
  b.name = "hand_r";
  b.waypoints = {{0.5, {0, 0, 1}}, {1.5, {0.4, 0, 1}}, {3.5, {0.4, 0.2, 1.4}, math::expSO3(math::Vector3(0, -1.2, 0))}};
  o.bodies = {b};
  SyntheticSource src(o);
  const auto at = [&](std::uint64_t k) { return src.frameAt(k).bodies[0].pose.p; };
  EXPECT_LT((at(0) - math::Vector3(0, 0, 1)).norm(), 1e-12);    // before the first: held
  EXPECT_LT((at(50) - math::Vector3(0, 0, 1)).norm(), 1e-12);
  EXPECT_LT((at(100) - math::Vector3(0.2, 0, 1)).norm(), 1e-12);  // halfway through the first segment
  const double s14 = 10.0 / 64 - 15.0 / 256 + 6.0 / 1024;           // s(1/4)
  EXPECT_LT((at(75) - math::Vector3(0.4 * s14, 0, 1)).norm(), 1e-12);
  EXPECT_LT((at(150) - math::Vector3(0.4, 0, 1)).norm(), 1e-12);  // at rest on the second
  EXPECT_LT((at(250) - math::Vector3(0.4, 0.1, 1.2)).norm(), 1e-12);
  EXPECT_LT((at(400) - math::Vector3(0.4, 0.2, 1.4)).norm(), 1e-12);  // after the last: held
  // the orientation turns with the same law: half of the 1.2 rad about −y halfway, all of it at the end
  EXPECT_LT((src.frameAt(150).bodies[0].pose.R - math::Matrix3::Identity()).norm(), 1e-12);
  EXPECT_LT((src.frameAt(250).bodies[0].pose.R - math::expSO3(math::Vector3(0, -0.6, 0))).norm(), 1e-12);
  EXPECT_LT((src.frameAt(400).bodies[0].pose.R - math::expSO3(math::Vector3(0, -1.2, 0))).norm(), 1e-12);
  // at rest at a waypoint: the speed there is 0 (one sample either side differs by O(dt³))
  EXPECT_LT((at(151) - at(149)).norm(), 1e-5);
  SyntheticBody bad = b;
  bad.waypoints[2].t = 1.5;
  o.bodies = {bad};
  try {
    SyntheticSource s2(o);
    ADD_FAILURE() << "waypoints not increasing in time accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'hand_r' waypoint 2"), std::string::npos) << e.what();
  }
}

TEST(MocapConfig, ShippedFilesAreFoundFromAnotherWorkingDirectory) {
  const std::filesystem::path old = std::filesystem::current_path();
  std::filesystem::current_path(std::filesystem::temp_directory_path());
  std::unique_ptr<Source> bvh;
  std::string error;
  try {
    bvh = makeSource(configOf(
        "source: bvh\nbvh:\n  file: data/bvh/cmu_max_131_03.bvh\n  map: configs/mappings/cmu.yaml\n  bodies: [pelvis]\n"));
    makeSource(configOf("source: bvh\nbvh:\n  file: data/bvh/nothing_here.bvh\n  bodies: {pelvis: Hips}\n"));
  } catch (const core::ConfigError& e) {
    error = e.what();
  }
  std::filesystem::current_path(old);
  ASSERT_NE(bvh, nullptr) << error;
  EXPECT_EQ(bvh->kind(), "bvh");
  EXPECT_NE(error.find("test.yaml:3: field 'bvh.file': data/bvh/nothing_here.bvh: not found"), std::string::npos) << error;
}

// The shipped C3D source config (configs/sim/mocap_c3d.yaml): the lab capture's marker clusters as rigid
// bodies, the pelvis in the lab frame in metres (the sample's markers are in mm), flagged for calibration first.
TEST(MocapConfig, TheShippedC3dConfigStreamsTheMarkerClustersAsBodies) {
  // the shipped file, played once and as fast as it reads (not paced, no loop)
  const std::string path = core::findData("configs/sim/mocap_c3d.yaml");
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("  loop: true\n");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 13, "  loop: false\n  paced: false\n");
  auto src = makeSource(core::ConfigNode::parse(text, path));
  ASSERT_EQ(src->kind(), "c3d");
  const auto f = src->next(std::chrono::milliseconds(0));
  ASSERT_TRUE(f.has_value());
  EXPECT_TRUE(f->calibration_pose);
  std::map<std::string, const mocap::Body*> bodies;
  for (const mocap::Body& b : f->bodies) bodies[b.name] = &b;
  for (const char* name : {"pelvis", "thigh_r", "shank_r", "foot_r", "thigh_l", "shank_l", "foot_l"}) EXPECT_EQ(bodies.count(name), 1u) << name;
  ASSERT_EQ(bodies.count("pelvis"), 1u);
  // a walking adult's pelvis markers are about a metre above the lab floor, whenever the pelvis is tracked
  int frames = 0, tracked = 0;
  for (auto g = f; g && frames < 450; g = src->next(std::chrono::milliseconds(0)), ++frames)
    for (const mocap::Body& b : g->bodies)
      if (b.name == "pelvis" && b.tracked) {
        ++tracked;
        EXPECT_GT(b.pose.p.z(), 0.7) << "frame " << frames;
        EXPECT_LT(b.pose.p.z(), 1.3) << "frame " << frames;
      }
  std::printf("c3d source: pelvis tracked in %d of %d frames\n", tracked, frames);
  EXPECT_EQ(frames, 450);
  EXPECT_GT(tracked, frames / 2);
}

TEST(MocapConfig, BuildsSourcesAndNamesFileLineAndField) {
  auto bvh = makeSource(configOf(
      "source: bvh\nbvh:\n  file: data/bvh/cmu_max_131_03.bvh\n  map: configs/mappings/cmu.yaml\n  bodies: [pelvis, head]\n"));
  EXPECT_EQ(bvh->kind(), "bvh");
  auto syn = makeSource(configOf("source: synthetic\nsynthetic:\n  bodies:\n    - {name: a, center: [0, 0, 1]}\n"));
  EXPECT_EQ(syn->kind(), "synthetic");
  auto expectError = [](const std::string& yaml, const std::string& what) {
    try {
      makeSource(configOf(yaml));
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expectError("source: kinect\n", "test.yaml:1: field 'source': unknown source 'kinect'");
  expectError("source: bvh\nbvh:\n  file: data/bvh/cmu_max_131_03.bvh\n  bodies: {pelvis: Hips}\n  rat: 2\n",
              "test.yaml:5: field 'bvh.rat': unknown key");
  expectError("source: bvh\nbvh:\n  file: data/bvh/cmu_max_131_03.bvh\n  map: configs/mappings/cmu.yaml\n  bodies: [pelvis, tail]\n",
              "field 'bvh.bodies[1]': body 'tail' is not a segment");
  expectError("source: bvh\nbvh:\n  file: data/bvh/cmu_max_131_03.bvh\n  bodies: {pelvis: Hips}\n  rate: -1\n",
              "test.yaml:5: field 'bvh.rate'");
  expectError("source: synthetic\nsynthetic:\n  rate_hz: abc\n  bodies: []\n", "field 'synthetic.rate_hz': 'abc' is not a number");
  expectError("source: synthetic\nsynthetic:\n  bodies:\n    - {name: a, center: [0, 0]}\n", "expected [x, y, z]");
  expectError("source: synthetic\nsynthetic:\n  bodies:\n    - {name: a, center: [0, 0, 1], waypoints: [{t: 0, xyz: [0, 0, 1]}]}\n",
              "field 'synthetic.bodies[0].center': 'center' and 'waypoints' exclude each other");
  expectError("source: synthetic\nsynthetic:\n  bodies:\n    - name: a\n      waypoints:\n        - {t: 1, xyz: [0, 0, 1]}\n"
              "        - {t: 0.5, xyz: [0, 0, 1]}\n",
              "test.yaml:7: field 'synthetic.bodies[0].waypoints[1].t': waypoint times must increase");
  expectError("source: synthetic\nsynthetic:\n  bodies:\n    - {name: a, waypoints: [{t: 0, at: [0, 0, 1]}]}\n", "unknown key");
  expectError("source: dtrack2\ndtrack2:\n  port: 99999\n  bodies: {0: head}\n", "field 'dtrack2.port'");
  expectError("source: c3d\nc3d:\n  file: data/c3d/sample01_Eb015pr.c3d\n  mapping: configs/mappings/nothing.yaml\n",
              "test.yaml:4: field 'c3d.mapping': configs/mappings/nothing.yaml: not found");
  expectError("source: c3d\nc3d:\n  file: data/c3d/sample01_Eb015pr.c3d\n  mapping: configs/mappings/c3d_sample01.yaml\n  loops: true\n",
              "test.yaml:5: field 'c3d.loops': unknown key");
  expectError("source: c3d\nc3d:\n  file: data/c3d/sample01_Eb015pr.c3d\n  mapping: configs/mappings/c3d_sample01.yaml\n  end_frame: 9999\n",
              "test.yaml:3: field 'c3d': ");
  EXPECT_THROW(core::ConfigNode::parse("a: [1, 2\n", "bad.yaml"), core::ConfigError);
}
