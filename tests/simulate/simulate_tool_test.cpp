// mannequin-simulate as a separate process (build/bin/mannequin-simulate): --help, a bad config's
// FILE:LINE and exit 2, the JSON summary of 1 s of the shipped demo (every key, finite numbers, the same
// numbers twice but for the wall-clock ones), and the --out MCAP file read back as sim.world messages.
#include <gtest/gtest.h>
#include <mannequin/v1/world.pb.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>

#include "mannequin/recording/mcap_reader.hpp"

namespace fs = std::filesystem;

namespace {

// the tool lands in build/bin, the test binary in build/bin/tests
fs::path toolPath() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "mannequin-simulate"; }

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("simulate_tool_test_" + std::to_string(::getpid()) + "_" + name);
}

struct ToolRun {
  int status = -1;
  std::string out, err;
};

// Runs the tool under timeout(1) (a hung run fails at the deadline instead of hanging the suite);
// stdout captured, stderr to a file.
ToolRun run(const std::string& args, int timeout_s = 240) {
  ToolRun r;
  const fs::path err = temp("stderr");
  const std::string cmd = "timeout " + std::to_string(timeout_s) + " " + toolPath().string() + " " + args + " 2>" + err.string();
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  fs::remove(err);
  return r;
}

const char* kKeys[] = {"frames", "steps", "sim_time_s", "wall_s", "nan_steps", "lcp_failures", "max_penetration_m",
                       "max_contacts", "mean_contacts", "foot_contact_fraction", "min_balance_distance_m",
                       "worst_joint_limit_excess_rad", "mean_hand_error_m", "mean_foot_error_m", "realtime_factor"};

// The number of "key": in a flat JSON object; nullopt when absent or not a number (null included).
std::optional<double> number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": (-?[0-9][0-9.eE+-]*)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return std::nullopt;
  return std::stod(m[1].str());
}

// The JSON without the wall-clock keys (the rest must be bit-identical between runs).
std::string withoutWallClock(std::string json) {
  for (const char* k : {"wall_s", "realtime_factor"})
    json = std::regex_replace(json, std::regex(std::string("\"") + k + "\": [^,}]*"), std::string("\"") + k + "\": _");
  return json;
}

}  // namespace

TEST(SimulateTool, HelpExitsZero) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  const ToolRun r = run("--help");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("--duration"), std::string::npos) << r.out;
}

TEST(SimulateTool, BadConfigNamesFileAndLineAndExitsTwo) {
  const fs::path cfg = temp("bad.yaml");
  std::ofstream(cfg) << "name: sim\nstep: 0.001\nphysics: {enabled: true, scene: configs/scenes/floor.yaml, friction_edge: 4}\n"
                        "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {pelvis: pelvis}}\n";
  const ToolRun r = run("--config " + cfg.string() + " --json");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(cfg.string() + ":3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("friction_edge"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;

  // a scene file with an error: its own FILE:LINE
  const fs::path scene = temp("bad_scene.yaml");
  std::ofstream(scene) << "name: s\nbodies:\n  - name: floor\n    shapes: [{type: plane, normal: [0, 0, 1], offset: 0}]\n"
                          "  - name: ball\n    shapes: [{type: sphere, radius: -1}]\n";
  const ToolRun s = run("--scene " + scene.string() + " --json");
  EXPECT_EQ(s.status, 2) << s.err;
  EXPECT_NE(s.err.find(scene.string() + ":"), std::string::npos) << s.err;
  fs::remove(cfg);
  fs::remove(scene);
}

TEST(SimulateTool, ShortDemoRunIsOneDeterministicJsonObjectWithFiniteNumbers) {
  const ToolRun a = run("--config configs/sim/sim_demo.yaml --duration 1 --json");
  ASSERT_EQ(a.status, 0) << a.err;
  // exactly one JSON object on stdout
  ASSERT_FALSE(a.out.empty());
  EXPECT_EQ(a.out.front(), '{') << a.out;
  EXPECT_EQ(a.out.find('{', 1), std::string::npos) << a.out;
  EXPECT_EQ(a.out.substr(a.out.find('}')), "}\n") << a.out;
  for (const char* k : kKeys) {
    // the balance distance exists only while a support is known (World::mannequinDiagnostics): null otherwise
    if (std::string(k) == "min_balance_distance_m" && a.out.find("\"min_balance_distance_m\": null") != std::string::npos)
      continue;
    const auto v = number(a.out, k);
    ASSERT_TRUE(v.has_value()) << k << " missing or not a number in " << a.out;
    EXPECT_TRUE(std::isfinite(*v)) << k;
  }
  // 1 s of 1 ms steps; a 120 Hz capture feeds about 120 frames
  EXPECT_EQ(*number(a.out, "steps"), 1000.0) << a.out;
  EXPECT_NEAR(*number(a.out, "sim_time_s"), 1.0, 1e-9);
  EXPECT_GE(*number(a.out, "frames"), 100.0);
  EXPECT_EQ(*number(a.out, "nan_steps"), 0.0);
  const double fraction = *number(a.out, "foot_contact_fraction");
  EXPECT_GE(fraction, 0.0);
  EXPECT_LE(fraction, 1.0);
  EXPECT_GE(*number(a.out, "max_contacts"), *number(a.out, "mean_contacts"));
  // the physical claims of the demo's first second (standing, then the start of the walk): the feet on
  // the floor, the real geometry less than 1 cm in it, hands and feet following the capture within 5 cm
  EXPECT_GT(*number(a.out, "max_contacts"), 0.0) << a.out;
  EXPECT_GT(fraction, 0.5) << a.out;
  EXPECT_LT(*number(a.out, "max_penetration_m"), 0.01) << a.out;
  EXPECT_LT(*number(a.out, "mean_hand_error_m"), 0.05) << a.out;
  EXPECT_LT(*number(a.out, "mean_foot_error_m"), 0.05) << a.out;
  EXPECT_LT(*number(a.out, "worst_joint_limit_excess_rad"), 0.1) << a.out;

  const ToolRun b = run("--config configs/sim/sim_demo.yaml --duration 1 --json");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(withoutWallClock(a.out), withoutWallClock(b.out));
}

TEST(SimulateTool, OutFileHoldsSimWorldMessagesAtTheWorldRate) {
  const fs::path mcap = temp("run.mcap");
  const ToolRun r = run("--config configs/sim/sim_demo.yaml --duration 0.5 --out " + mcap.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const mannequin::recording::McapReader reader = mannequin::recording::McapReader::open(mcap.string());
  EXPECT_TRUE(reader.indexed());
  ASSERT_EQ(reader.channels().size(), 1u);
  const auto& channel = reader.channels().begin()->second;
  EXPECT_EQ(channel.topic, "sim.world");
  EXPECT_EQ(reader.schemas().at(channel.schema_id).name, "mannequin.v1.WorldState");
  const auto messages = reader.readAll();
  EXPECT_EQ(messages.size(), 30u);  // 0.5 s at the demo's world_rate of 60 Hz
  std::uint64_t last_step = 0;
  int with_foot_contact = 0, floor_contacts = 0;
  for (const auto& m : messages) {
    mannequin::v1::WorldState w;
    ASSERT_TRUE(w.ParseFromString(m.data));
    EXPECT_EQ(w.header().schema_version(), 1u);
    EXPECT_GT(w.step(), last_step);
    last_step = w.step();
    ASSERT_EQ(w.mannequins_size(), 1);
    EXPECT_EQ(w.mannequins(0).name(), "operator");
    // the demo's physics on the wire: the step's diagnostics, the mannequin's foot contact and contacts
    ASSERT_TRUE(w.has_diagnostics());
    EXPECT_EQ(w.diagnostics().contacts(), w.mannequins(0).contact_count());
    EXPECT_GE(w.diagnostics().max_penetration_m(), 0.0);
    EXPECT_NE(w.diagnostics().solver(), "failed");
    EXPECT_EQ(w.mannequins(0).contacts_size(), w.mannequins(0).contact_count());
    with_foot_contact += w.mannequins(0).foot_contact();
    for (const auto& c : w.mannequins(0).contacts()) {
      EXPECT_GE(c.normal_force(), 0.0);
      EXPECT_GE(c.friction_force(), 0.0);
      EXPECT_NEAR(std::hypot(c.normal().x(), c.normal().y(), c.normal().z()), 1.0, 1e-9);
      floor_contacts += (c.body_a().find("floor") != std::string::npos || c.body_b().find("floor") != std::string::npos);
    }
  }
  EXPECT_GT(with_foot_contact, 15) << "the demo starts standing";
  EXPECT_GT(floor_contacts, 0);
  fs::remove(mcap);
}
