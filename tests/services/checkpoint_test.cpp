// The sim's checkpoint (simservice/checkpoint.hpp, sim::World::checkpoint/restore): a World put back from
// its checkpoint file is the World it was (pose exact, calibration, step), continues like it, holds its
// pose until the mocap comes back; a corrupt or mismatched checkpoint is refused naming why, the World
// unchanged, and the service then starts fresh instead of failing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "mannequin/math/so3.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/simservice/checkpoint.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/simservice/sim_service.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "../common/error_log.hpp"
#include "../common/pose.hpp"
using namespace mannequin;
using namespace mannequin::sim;

namespace {
using mannequin::testing::pose;

mocap::Frame actor(std::int64_t stamp_ns, const math::Vector3& hand_offset) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  // an actor 2 m away, turned 90° about z
  f.bodies = {{"pelvis", pose({2, 1, 0.95}, {0, 0, M_PI / 2}), true}, {"hand_l", pose(math::Vector3(2.3, 1.2, 0.9) + hand_offset), true}};
  return f;
}

std::vector<MannequinSetup> checkpointMannequin(const std::string& model_file = "configs/mannequins/male_50th.yaml") {
  MannequinSetup s;
  s.name = "operator";
  s.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(model_file));
  s.frames = {{"pelvis", "pelvis"}, {"hand_l", "hand_l"}};
  return {std::move(s)};
}

// A World calibrated on the actor, its hand moved 5 cm up and followed for 0.3 s.
void drive(World& w) {
  w.addMocap(actor(0, math::Vector3::Zero()));
  w.anchor(0);
  w.addMocap(actor(1'000'000, math::Vector3(0, 0, 0.05)));
  for (int k = 0; k < 300; ++k) w.step();
}

// The checkpoint bytes of a World, as the sim service writes them.
std::string checkpointBytes(const World& w) {
  v1::WorldState state;
  simservice::toWorldState(w, nullptr, false, false, state);
  v1::SimCheckpoint c;
  simservice::toCheckpoint(w, state, 123, c);
  return simservice::encodeCheckpoint(c);
}

std::string checkpointDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto p = std::filesystem::temp_directory_path() / ("mq-ckpt-" + std::string(info->name()) + "-" + std::to_string(getpid()));
  std::filesystem::create_directories(p);
  return p.string();
}

template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST(SimCheckpoint, AWorldRestoredFromItsCheckpointFileIsWhereItWasAndContinuesLikeIt) {
  SimConfig cfg;
  World original(checkpointMannequin(), cfg);
  drive(original);
  ASSERT_TRUE(original.calibrated(0));
  ASSERT_GT(original.q(0)(0), 1.5);  // far from the initial pose (standing at the origin)

  const std::string dir = checkpointDir();
  const std::string file = dir + "/sim.checkpoint";
  simservice::writeCheckpointFile(file, checkpointBytes(original));
  EXPECT_FALSE(std::filesystem::exists(file + ".tmp"));
  const v1::SimCheckpoint read = simservice::readCheckpoint(file);
  EXPECT_EQ(read.written_ns(), 123);

  World restored(checkpointMannequin(), cfg);
  const std::vector<std::string> notes = simservice::restoreWorld(restored, read);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes[0].find("velocities"), std::string::npos);
  // the pose exactly (doubles carried as they are), the calibration, the step
  ASSERT_EQ(restored.q(0).size(), original.q(0).size());
  for (Eigen::Index k = 0; k < original.q(0).size(); ++k) EXPECT_EQ(restored.q(0)(k), original.q(0)(k)) << "q(" << k << ")";
  EXPECT_TRUE(restored.calibrated(0));
  EXPECT_EQ(restored.stepCount(), original.stepCount());
  for (std::size_t i = 0; i < 2; ++i) {
    const DrivenFrame& a = original.controlFrames(0)[i];
    const DrivenFrame& b = restored.controlFrames(0)[i];
    EXPECT_LT((a.offset.p - b.offset.p).norm(), 1e-12) << a.frame;
    EXPECT_LT(math::logSO3(a.offset.R.transpose() * b.offset.R).norm(), 1e-9) << a.frame;  // via a quaternion
    EXPECT_LT((a.actual.p - b.actual.p).norm(), 1e-12) << a.frame;
  }

  // no mocap yet (the restarted sim's source is not anchored): it holds the restored pose
  World held(checkpointMannequin(), cfg);
  simservice::restoreWorld(held, read);
  for (int k = 0; k < 200; ++k) held.step();
  EXPECT_LT((held.q(0).head<3>() - original.q(0).head<3>()).norm(), 1e-3);
  EXPECT_LT((held.controlFrames(0)[1].actual.p - original.controlFrames(0)[1].actual.p).norm(), 1e-3);

  // the mocap again (a new capture clock, as a restarted service sees it): both follow the same way,
  // with no new calibration (the offsets of the first one)
  for (World* w : {&original, &restored}) {
    w->addMocap(actor(5'000'000'000, math::Vector3(0, 0.05, 0.05)));
    w->anchor(5'000'000'000);
    for (int k = 0; k < 100; ++k) w->step();
  }
  EXPECT_LT((restored.q(0) - original.q(0)).norm(), 1e-9);
  std::filesystem::remove_all(dir);
}

TEST(SimCheckpoint, ACorruptOrMismatchedCheckpointIsRefusedNamingWhyAndTheWorldIsUnchanged) {
  SimConfig cfg;
  World source(checkpointMannequin(), cfg);
  drive(source);
  const std::string bytes = checkpointBytes(source);
  const std::string dir = checkpointDir();
  const std::string file = dir + "/sim.checkpoint";

  // the file: missing, not a checkpoint, truncated, a flipped byte
  EXPECT_NE(errorOf([&] { simservice::readCheckpoint(file); }).find(file + ": cannot open"), std::string::npos);
  std::ofstream(file) << "name: not a checkpoint\n";
  EXPECT_NE(errorOf([&] { simservice::readCheckpoint(file); }).find("not a mannequin-sim checkpoint"), std::string::npos);
  simservice::writeCheckpointFile(file, bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(errorOf([&] { simservice::readCheckpoint(file); }).find("truncated"), std::string::npos);
  std::string flipped = bytes;
  flipped[flipped.size() - 20] = static_cast<char>(flipped[flipped.size() - 20] ^ 0x10);
  simservice::writeCheckpointFile(file, flipped);
  EXPECT_NE(errorOf([&] { simservice::readCheckpoint(file); }).find("corrupt"), std::string::npos);

  // a good file that does not fit: another model, NaN, another mannequin, a missing calibration
  const v1::SimCheckpoint good = simservice::decodeCheckpoint(bytes, "test");
  World w(checkpointMannequin(), cfg);
  const skeleton::VectorX q0 = w.q(0);
  const auto refused = [&](v1::SimCheckpoint c, const std::string& expected) {
    const std::string e = errorOf([&] { simservice::restoreWorld(w, c); });
    EXPECT_NE(e.find(expected), std::string::npos) << e;
    EXPECT_FALSE(w.calibrated(0)) << expected;
    EXPECT_EQ(w.q(0), q0) << expected;
    EXPECT_EQ(w.stepCount(), 0u) << expected;
  };
  v1::SimCheckpoint c = good;
  c.mutable_world()->mutable_mannequins(0)->set_model("another_model");
  refused(c, "model 'another_model'");
  c = good;
  c.mutable_world()->mutable_mannequins(0)->set_q(3, std::nan(""));
  refused(c, "q is not finite");
  c = good;
  c.mutable_world()->mutable_mannequins(0)->mutable_q()->RemoveLast();
  refused(c, "coordinates");
  c = good;
  c.mutable_world()->mutable_mannequins(0)->set_name("visitor");
  c.mutable_calibration(0)->set_name("visitor");
  refused(c, "no mannequin 'operator'");
  c = good;
  c.clear_calibration();
  refused(c, "no calibration");
  c = good;
  c.mutable_calibration(0)->mutable_offsets(0)->mutable_pose()->mutable_position()->set_x(std::nan(""));
  refused(c, "offset");
  // another model file with the same frames: a model of another name
  World other(checkpointMannequin("configs/mannequins/male_95th.yaml"), cfg);
  EXPECT_NE(errorOf([&] { simservice::restoreWorld(other, good); }).find("model"), std::string::npos);

  // the service: a corrupt --resume file is logged and the sim starts fresh (no throw)
  simservice::writeCheckpointFile(file, flipped);
  simservice::SimServiceConfig sc = simservice::loadSimConfig("configs/sim/sim_demo.yaml");
  sc.collision.mode = simservice::CollisionMode::kNone;
  sc.publish = {"ipc://" + dir + "/sim"};
  sc.connect.clear();
  sc.resume = file;
  zmq::context_t ctx;
  {
    mannequin::testing::ExpectErrorLog refused_logged;  // "checkpoint refused, starting fresh ..."
    EXPECT_NO_THROW(simservice::SimService(sc, ctx));
  }
  std::filesystem::remove_all(dir);
}
