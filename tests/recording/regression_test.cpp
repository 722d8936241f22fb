// A recording is a test: a mocap stream recorded from mannequin-mocap is replayed into a fresh
// mannequin-sim + mannequin-collision pair in deterministic (replay) mode, twice — once as fast as
// possible, once in lockstep with the sim — and every sim.world of the second run must be
// byte-identical to the recorded one of the first (same build: no floating-point tolerance is
// needed, none is used).
//
// With collision in the loop: in replay mode mannequin-sim waits for the contacts of each query
// (commit 471f4cc); before that the contacts of a world depended on timing (~10 of 156 worlds
// differed). Not covered: scenario triggers (no scenario service yet).
//
// Every wait is on a condition with a deadline that fails the test naming it; the processes are
// signalled only through core::signalProcess (tests/common/child_process.hpp) and never left behind.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include <google/protobuf/util/message_differencer.h>
#include <mannequin/v1/health.pb.h>
#include <mannequin/v1/world.pb.h>
#include "../common/child_process.hpp"
#include "test_files.hpp"
#include "../common/source.hpp"

namespace fs = std::filesystem;
using namespace mannequin::recording;
using namespace mannequin::recording::testing;

namespace {

fs::path binDir() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path(); }

using mannequin::testing::sourceDir;

using namespace std::chrono_literals;

using mannequin::testutil::Child;

// The number of messages on `topic` in an MCAP file (0 when it cannot be read yet).
std::size_t countMessages(const fs::path& file, const std::string& topic) {
  try {
    ReadFilter f;
    f.topics = {topic};
    return McapReader::open(file.string()).readAll(f).size();
  } catch (const McapError&) {
    return 0;
  }
}

class ReplayRegression : public ::testing::Test {
 protected:
  // collision: run mannequin-collision with the sim (lockstep by step number)
  void prepare(bool collision) {
    collision_ = collision;
    if (collision && !fs::exists(binDir() / "mannequin-collision")) GTEST_SKIP() << "mannequin-collision is not built";
    for (const char* tool : {"mannequin-mocap", "mannequin-sim", "mannequin-record", "mannequin-replay"}) {
      if (!fs::exists(binDir() / tool)) GTEST_SKIP() << tool << " is not built";
    }
    dir_ = tempPath("regression");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // the shipped demo sim config (physics on, as in configs/sim/sim_demo.yaml), in replay (deterministic) mode. sim.world at
    // 60 Hz of simulation time only: publish_on_mocap would make the number of worlds depend on how
    // the frames are batched on arrival (143 worlds for 315 frames replayed --fast, 366 in lockstep)
    spit(dir_ / "sim.yaml", R"(name: sim
publish: ipc:///unused
connect: []
mode: replay
step: 0.001
world_rate: 60
publish_on_mocap: false
interpolation_delay: 0.0084
occlusion: {hold: 0.3, blend: 0.5}
calibration: {needs_flag: false}
stepper: controller
collision: )" + std::string(collision_ ? "{mode: service, period_steps: 10, replay_deadline: 5.0, margin: 0.02}"
                                                  : "{mode: none}") + R"(
physics: {enabled: true, gravity: [0, 0, -9.81], scene: configs/scenes/floor.yaml, segment_margin: 0.005, segment_material: skin, query_period_steps: 1,
          activation_distance: 0.02, calibration_clearance: 0.002, friction_edges: 4, recovery_speed: 0.5, max_rows: 512}
mannequins:
  - name: operator
    config: configs/mannequins/male_50th.yaml
    root_frame: pelvis
    controller: configs/control/mocap.yaml
    control_frames: {pelvis: pelvis, head: head, hand_l: hand_l, hand_r: hand_r, foot_l: foot_l, foot_r: foot_r}
)");
    // the shipped collision config (floor + the demo mannequin)
    spit(dir_ / "collision.yaml", R"(name: collision
publish: ipc:///unused
connect: []
scene: configs/scenes/floor.yaml
activation_distance: 0.02
mannequins:
  - {name: operator, config: configs/mannequins/male_50th.yaml, margin: 0.0, self_collision: true}
)");
  }
  void TearDown() override {
    if (dir_.empty()) return;
    if (!::testing::Test::HasFailure()) fs::remove_all(dir_);
  }
  std::string ep(const std::string& name) const { return "ipc://" + (dir_ / (name + ".ipc")).string(); }
  std::string bin(const std::string& tool) const { return (binDir() / tool).string(); }
  std::string log(const std::string& name) const { return slurp(dir_ / (name + ".log")); }

  // a fresh sim fed by a replay of `input`; its sim.world recorded into `out`
  void simRun(const std::string& tag, const fs::path& input, const fs::path& out, const std::vector<std::string>& replay_extra) {
    const std::string sim_ep = ep("sim-" + tag), replay_ep = ep("replay-" + tag);
    const std::string collision_ep = ep("collision-" + tag);
    std::unique_ptr<Child> collision;
    if (collision_) {
      collision = std::make_unique<Child>(std::vector<std::string>{bin("mannequin-collision"), "--config", (dir_ / "collision.yaml").string(),
                                                                   "--publish", collision_ep, "--connect", sim_ep, "--log-level", "warn"},
                                          dir_ / ("collision-" + tag + ".log"));
      ASSERT_TRUE(collision->started());
    }
    std::vector<std::string> sim_args = {bin("mannequin-sim"), "--config", (dir_ / "sim.yaml").string(), "--publish",
                                         sim_ep, "--connect", replay_ep, "--log-level", "warn"};
    if (collision_) sim_args.insert(sim_args.end(), {"--connect", collision_ep});
    Child sim(sim_args, dir_ / ("sim-" + tag + ".log"));
    ASSERT_TRUE(sim.started());
    // the replay must not start before the recorder is subscribed to the sim: a fast replay is over
    // in milliseconds, and what the sim publishes before the recorder's subscription reaches it is
    // lost (PUB/SUB). The recorder also records the sim's heartbeats (every 0.5 s): once the
    // heartbeat channel is in its file (Channel records are written at once), it is subscribed.
    const fs::path sim_socket = dir_ / ("sim-" + tag + ".ipc");
    for (int i = 0; i < 200 && !fs::exists(sim_socket); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_TRUE(fs::exists(sim_socket)) << log("sim-" + tag);
    Child rec({bin("mannequin-record"), "--connect", sim_ep, "--topics", "sim.world,health.heartbeat", "--out", out.string(),
               "--duration", "60", "--progress", "0", "--flush-interval", "0.1"},
              dir_ / ("record-" + tag + ".log"));
    ASSERT_TRUE(rec.started());
    for (int i = 0; i < 300 && slurp(out).find("health.heartbeat") == std::string::npos; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_NE(slurp(out).find("health.heartbeat"), std::string::npos) << log("record-" + tag) << log("sim-" + tag);
    std::vector<std::string> args = {bin("mannequin-replay"), input.string(), "--publish", replay_ep, "--topics",
                                     "mocap.frame", "--wait-subscribers", "10", "--progress", "0"};
    args.insert(args.end(), replay_extra.begin(), replay_extra.end());
    Child replay(args, dir_ / ("replay-" + tag + ".log"));
    ASSERT_TRUE(replay.started());
    EXPECT_EQ(replay.wait(60s), 0) << log("replay-" + tag);
    // The sim has stepped through every frame once one of its heartbeats counts all of them delivered
    // (replay mode: the frames a poll delivers are stepped through before the next heartbeat), and the
    // recorder has every sim.world once that heartbeat is in its file (one publisher socket: the worlds
    // arrive before it). The file is read back by the recovery scan (no footer yet).
    const std::size_t frames = countMessages(input, "mocap.frame");
    ASSERT_GT(frames, 0U) << input;
    std::optional<mannequin::v1::Heartbeat> done;
    std::uint64_t delivered = 0;  // the most frames a recorded heartbeat has counted
    const auto until = std::chrono::steady_clock::now() + 60s;
    while (!done && std::chrono::steady_clock::now() < until) {
      try {
        ReadFilter f;
        f.topics = {"health.heartbeat"};
        for (const Message& m : McapReader::open(out.string()).readAll(f)) {
          mannequin::v1::Heartbeat hb;
          if (!hb.ParseFromString(m.data)) continue;
          for (const auto& t : hb.topics())
            if (t.topic() == "mocap.frame" && !t.published()) {
              delivered = std::max<std::uint64_t>(delivered, t.messages());
              if (t.messages() >= frames && !done) done = hb;
            }
        }
      } catch (const McapError&) {
        // not readable yet
      }
      if (!done) std::this_thread::sleep_for(100ms);
    }
    ASSERT_TRUE(done.has_value()) << "within 60 s no heartbeat of the sim recorded in " << out << " counts the " << frames
                      << " mocap frames replayed (at most " << delivered << ")\n"
                      << log("sim-" + tag) << log("record-" + tag);
    std::uint64_t published = 0;
    for (const auto& t : done->topics())
      if (t.topic() == "sim.world" && t.published()) published = t.messages();
    EXPECT_EQ(rec.stop(20s), 0) << log("record-" + tag);
    EXPECT_EQ(countMessages(out, "sim.world"), published) << "sim.world recorded vs published by the sim";
    EXPECT_EQ(sim.stop(20s), 0) << log("sim-" + tag);
    if (collision) {
      EXPECT_EQ(collision->stop(20s), 0) << log("collision-" + tag);
    }
  }

  fs::path dir_;
  bool collision_ = false;


  void run();
};

TEST_F(ReplayRegression, EverySimWorldIsByteIdenticalToTheRecordedOne) {
  prepare(false);
  if (IsSkipped()) return;
  run();
}

TEST_F(ReplayRegression, WithCollisionEverySimWorldIsByteIdentical) {
  prepare(true);
  if (IsSkipped()) return;
  run();
}

void ReplayRegression::run() {
  // 1. record a mocap stream (the shipped CMU capture played as a tracker streams it, 120 Hz)
  const fs::path mocap = dir_ / "mocap.mcap";
  const std::string mocap_cfg = sourceDir() + "/configs/sim/mocap_demo.yaml";
  Child rec({bin("mannequin-record"), "--connect", ep("mocap"), "--topics", "mocap.frame", "--out", mocap.string(), "--duration",
             "3.0", "--progress", "0"},
            dir_ / "record-mocap.log");
  ASSERT_TRUE(rec.started());
  Child src({bin("mannequin-mocap"), "--config", mocap_cfg, "--publish", ep("mocap"), "--duration", "2.8", "--log-level", "warn"},
            dir_ / "mocap.log");
  ASSERT_TRUE(src.started());
  EXPECT_EQ(src.wait(30s), 0) << log("mocap");
  ASSERT_EQ(rec.wait(30s), 0) << log("record-mocap");
  const McapReader input = McapReader::open(mocap.string());
  ASSERT_GT(input.statistics().message_count, 200U) << log("record-mocap");  // 120 Hz for ~2.5 s

  // 2. golden run: replay as fast as possible into a fresh sim; the recording of its sim.world is the reference
  const fs::path world1 = dir_ / "world1.mcap";
  simRun("golden", mocap, world1, {"--fast"});
  // the reference file: the input stream plus the recorded outputs, as one MCAP file
  const fs::path golden = dir_ / "golden.mcap";
  {
    const McapReader w1 = McapReader::open(world1.string());
    McapWriter w(golden.string());
    std::map<std::pair<int, std::uint16_t>, std::uint16_t> channel_of;
    int file = 0;
    for (const McapReader* r : {&input, &w1}) {
      std::map<std::uint16_t, std::uint16_t> schema_of;
      for (const auto& [id, s] : r->schemas()) schema_of[id] = w.addSchema(s.name, s.encoding, s.data);
      for (const auto& [id, c] : r->channels()) {
        channel_of[{file, id}] = w.addChannel(c.topic, c.schema_id ? schema_of.at(c.schema_id) : 0, c.message_encoding);
      }
      for (const Message& m : r->readAll()) w.write(channel_of.at({file, m.channel_id}), m.sequence, m.log_time, m.publish_time, m.data);
      ++file;
    }
  }

  // 3. check run: a fresh sim fed by the golden file's mocap.frame, this time in lockstep with the sim
  const fs::path world2 = dir_ / "world2.mcap";
  // (a sim.world comes about every second mocap frame: ack every 2nd frame, short timeout)
  simRun("check", golden, world2,
         {"--lockstep", "sim.world", "--ack-connect", ep("sim-check"), "--ack-every", "2", "--ack-timeout", "0.2"});
  EXPECT_NE(log("replay-check").find("lockstep:"), std::string::npos) << log("replay-check");

  // 4. compare every sim.world
  const McapReader g = McapReader::open(golden.string());
  ReadFilter worlds;
  worlds.topics = {"sim.world"};
  const std::vector<Message> want = g.readAll(worlds);
  const std::vector<Message> got = McapReader::open(world2.string()).readAll(worlds);
  // 60 Hz of simulation time over the capture
  const double capture_s = (input.statistics().message_end_time - input.statistics().message_start_time) * 1e-9;
  ASSERT_GT(static_cast<double>(want.size()), 0.9 * 60.0 * capture_s) << log("sim-golden");
  ASSERT_EQ(got.size(), want.size()) << log("sim-check") << log("replay-check");
  std::size_t differing = 0, first = want.size();
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (got[i].data != want[i].data) {
      ++differing;
      first = std::min(first, i);
    }
  }
  std::string detail;
  if (differing > 0) {
    mannequin::v1::WorldState a, b;
    a.ParseFromString(want[first].data);
    b.ParseFromString(got[first].data);
    google::protobuf::util::MessageDifferencer diff;
    diff.ReportDifferencesToString(&detail);
    diff.Compare(a, b);
    detail = "\nstep " + std::to_string(a.step()) + ": contacts_step " + std::to_string(a.contacts_step()) + " -> " +
             std::to_string(b.contacts_step()) + ", contacts_stale " + std::to_string(a.contacts_stale()) + " -> " +
             std::to_string(b.contacts_stale()) + "\n" + detail.substr(0, 1500);
  }
  EXPECT_EQ(differing, 0U) << "first differing sim.world: #" << first << " of " << want.size() << detail;

  // the worlds are real: calibrated mannequin, contacts with the floor in time (never stale), the
  // soles never deeper in the floor than the segment margin (0.005 m: the contact rows keep the margin
  // shells from overlapping) and on the floor (≤ 1 cm) in most worlds
  std::size_t calibrated = 0, with_contacts = 0, stale = 0, on_floor = 0;
  double lowest = 1e9;
  for (const Message& m : want) {
    mannequin::v1::WorldState w;
    ASSERT_TRUE(w.ParseFromString(m.data));
    EXPECT_EQ(w.mode(), "replay");
    EXPECT_EQ(w.header().send_time_ns(), 0);
    ASSERT_EQ(w.mannequins_size(), 1);
    calibrated += w.mannequins(0).calibrated();
    with_contacts += w.mannequins(0).contacts_size() > 0;
    stale += w.contacts_stale();
    const double sole = w.mannequins(0).sole_height();  // NaN with the physics off: fails below
    EXPECT_GE(sole, -0.005) << "sim.world at step " << w.step() << ": sole below the floor by more than the segment margin";
    lowest = std::min(lowest, sole);
    on_floor += sole <= 0.01;
  }
  EXPECT_GT(calibrated, want.size() / 2);
  EXPECT_GT(on_floor, want.size() / 2) << "worlds with a sole within 1 cm of the floor; lowest sole " << lowest << " m";
  // the physics' floor contacts in most worlds (with collision on, the service's contacts are queried
  // in lockstep too — never stale — but sim.world carries the physics' own)
  EXPECT_GT(with_contacts, want.size() / 2) << "worlds with contacts reported";
  if (collision_) {
    EXPECT_EQ(stale, 0U);
  }
}

}  // namespace
