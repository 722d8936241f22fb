// mannequin-simulate as a separate process (build/bin/mannequin-simulate): --help, a bad config's
// FILE:LINE and exit 2, the JSON summary of 1 s of the shipped demo (every key, finite numbers, the same
// numbers twice but for the wall-clock ones), and the --out MCAP file read back as sim.world messages.
#include <gtest/gtest.h>
#include <mannequin/v1/world.pb.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <utility>

#include "../common/tool_run.hpp"
#include "mannequin/recording/mcap_reader.hpp"

namespace fs = std::filesystem;

namespace {

using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-simulate"; }

// Runs the tool under timeout(1) (a hung run fails at the deadline instead of hanging the suite).
ToolResult run(const std::string& args, int timeout_s = 240) {
  return mannequin::testutil::runTool(toolPath().string() + " " + args, timeout_s);
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

// Each test's files (temp(name)) in a directory of its own, removed after it.
class SimulateTool : public mannequin::testutil::TempDirTest {
 protected:
  // Runs python3 on `json` with `script` (d = json.loads of it); its exit status and stdout+stderr.
  std::pair<int, std::string> pythonOn(const std::string& json, const std::string& script) const {
    const fs::path in = temp("out.json");
    std::ofstream(in) << json;
    const ToolResult r = mannequin::testutil::runPython(
        dir_, "import json, sys\nd = json.loads(open(sys.argv[1]).read())\n" + script, in.string());
    return {r.exit_code, r.out};
  }
};

}  // namespace

TEST_F(SimulateTool, HelpExitsZero) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  const ToolResult r = run("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("--duration"), std::string::npos) << r.out;
}

TEST_F(SimulateTool, BadConfigNamesFileAndLineAndExitsTwo) {
  const fs::path cfg = temp("bad.yaml");
  std::ofstream(cfg) << "name: sim\nstep: 0.001\nphysics: {enabled: true, scene: configs/scenes/floor.yaml, friction_edge: 4}\n"
                        "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {pelvis: pelvis}}\n";
  const ToolResult r = run("--config " + cfg.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(cfg.string() + ":3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("friction_edge"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;

  // a scene file with an error: its own FILE:LINE
  const fs::path scene = temp("bad_scene.yaml");
  std::ofstream(scene) << "name: s\nbodies:\n  - name: floor\n    shapes: [{type: plane, normal: [0, 0, 1], offset: 0}]\n"
                          "  - name: ball\n    shapes: [{type: sphere, radius: -1}]\n";
  const ToolResult s = run("--scene " + scene.string() + " --json");
  EXPECT_EQ(s.exit_code, 2) << s.err;
  EXPECT_NE(s.err.find(scene.string() + ":"), std::string::npos) << s.err;
  fs::remove(cfg);
  fs::remove(scene);
}

TEST_F(SimulateTool, BadMannequinMocapAndCaptureFilesNameFileAndLineAndExitTwo) {
  // a mannequin config with a typo on line 3
  const fs::path mannequin = temp("bad_mannequin.yaml");
  std::ofstream(mannequin) << "name: m\nstature_m: 1.75\nmass_kgg: 70\n";
  const ToolResult m = run("--mannequin " + mannequin.string() + " --duration 0.01 --json");
  EXPECT_EQ(m.exit_code, 2) << m.err;
  EXPECT_NE(m.err.find(mannequin.string() + ":3"), std::string::npos) << m.err;
  EXPECT_NE(m.err.find("mass_kgg"), std::string::npos) << m.err;
  EXPECT_TRUE(m.out.empty()) << m.out;

  // a sim config whose `mocap` config (line 4 of the sim config names it) has a bad value on line 4
  const fs::path mocap = temp("bad_mocap.yaml");
  std::ofstream(mocap) << "name: mocap\nsource: bvh\nbvh:\n  rate: -2\n  file: data/bvh/cmu_max_131_03.bvh\n"
                          "  map: configs/mappings/cmu.yaml\n  bodies: [pelvis]\n";
  const fs::path cfg = temp("mocap_cfg.yaml");
  std::ofstream(cfg) << "name: sim\nstep: 0.001\nphysics: {enabled: true, scene: configs/scenes/floor.yaml}\nmocap: " << mocap.string()
                     << "\nmannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {pelvis: pelvis}}\n";
  const ToolResult c = run("--config " + cfg.string() + " --duration 0.01 --json");
  EXPECT_EQ(c.exit_code, 2) << c.err;
  EXPECT_NE(c.err.find(mocap.string() + ":4"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("rate"), std::string::npos) << c.err;
  // a mocap config that is neither a BVH capture nor a scripted one: the line of its `source`
  std::ofstream(mocap) << "name: mocap\n\nsource: dtrack2\ndtrack2: {port: 5000}\n";
  const ToolResult k = run("--config " + cfg.string() + " --duration 0.01 --json");
  EXPECT_EQ(k.exit_code, 2) << k.err;
  EXPECT_NE(k.err.find(mocap.string() + ":3"), std::string::npos) << k.err;
  // a scripted capture without an end: the line of its `synthetic` section, naming the duration
  std::ofstream(mocap) << "name: mocap\n\nsource: synthetic\nsynthetic: {rate_hz: 120}\n";
  const ToolResult e = run("--config " + cfg.string() + " --duration 0.01 --json");
  EXPECT_EQ(e.exit_code, 2) << e.err;
  EXPECT_NE(e.err.find(mocap.string() + ":4"), std::string::npos) << e.err;
  EXPECT_NE(e.err.find("duration"), std::string::npos) << e.err;

  // a broken BVH capture (--mocap): the BVH file's own line
  const fs::path bvh = temp("bad.bvh");
  std::ofstream(bvh) << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n";
  const ToolResult b = run("--mocap " + bvh.string() + " --duration 0.01 --json");
  EXPECT_EQ(b.exit_code, 2) << b.err;
  EXPECT_NE(b.err.find(bvh.string() + ":"), std::string::npos) << b.err;
  EXPECT_TRUE(b.out.empty()) << b.out;
  for (const fs::path& p : {mannequin, mocap, cfg, bvh}) fs::remove(p);
}

// The shipped leaning worker (configs/sim/sim_lean.yaml, docs/balance.md): the balance controller asks for
// ±150 N fore-aft pushes at the CoM. The feet alone hold at most ≈ 127 N (m g × half the sole length / CoM
// height), so the whole margin can only be held while the left hand is on the wall (the scripted actor puts it
// there around 4 s of the 8): some of the run, not all of it. The margin the World measures (the largest
// horizontal push in any of ±x, ±y the contacts hold) never drops to 0 (the posture always has an equilibrium).
TEST_F(SimulateTool, TheLeaningWorkerHoldsTheWholeMarginOnlyWithTheHandOnTheWall) {
  const ToolResult a = run("--config configs/sim/sim_lean.yaml --json", 300);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto [status, out] = pythonOn(
      a.out,
      "b = d['balance_controller']\nassert b['enabled'] is True, b\nassert b['failures'] == 0, b\n"
      "assert b['solves'] >= 800, b\nassert b['driving_fraction'] > 0.95, b\n"
      "assert 0.05 < b['full_margin_fraction'] < 0.95, b\n"
      "assert d['nan_steps'] == 0 and d['max_penetration_m'] < 0.01, d\n"
      "assert d['min_force_margin_n'] > 0, d\nassert abs(d['sim_time_s'] - 8.0) < 0.02, d\nprint('ok')");
  EXPECT_EQ(status, 0) << out << a.out;
  // the whole-body kinetics of the lean (docs/kinetics.md): it starts and ends at rest, so the floor and the
  // wall carry the weight on average (momentum balance, within the 3 % the method's filter and residual
  // allow); the 50th-percentile male weighs 78.5 kg
  const auto [k_status, k_out] = pythonOn(
      a.out,
      "k = d['kinetics']\nassert len(k) == 1 and k[0]['mannequin'] == 'operator', k\n"
      "k = k[0]\nassert abs(k['weight_n'] - 78.5 * 9.81) < 0.5, k\nassert k['samples'] >= 400, k\n"
      "assert abs(k['grf_mean_over_weight'] - 1.0) < 0.03, k\n"
      "assert abs(d['grf_mean_over_weight'] - k['grf_mean_over_weight']) < 1e-12, d\n"
      "assert k['residual_force_mean_n'] < 0.1 * k['weight_n'], k\nprint('ok')");
  EXPECT_EQ(k_status, 0) << k_out << a.out;
  // a bad balance controller setting: exit 2 naming the file, line and field
  const fs::path cfg = temp("bad_balance.yaml");
  std::ofstream(cfg) << "name: sim\nstep: 0.001\nphysics:\n  enabled: true\n  scene: configs/scenes/bay.yaml\n"
                        "  balance_controller: {enabled: true, force_margin: [[150, 0, 0]]}\n"
                        "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {pelvis: pelvis}}\n";
  const ToolResult r = run("--config " + cfg.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(cfg.string() + ":6"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("force_margin"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// The shipped box lift (configs/sim/sim_lift.yaml: CMU 115_02, 401 frames whose frame 0 is the converter's
// T-pose): the T-pose is skipped, so the run plays the 400 frames of the capture and calibrates on the first of
// them, the actor standing with the arms down.
TEST_F(SimulateTool, TheBoxLiftSkipsTheConvertersTPose) {
  const ToolResult a = run("--config configs/sim/sim_lift.yaml --json --log-level info", 300);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.err.find("cmu_115_02.bvh: frame 0 is a T-pose"), std::string::npos) << a.err;
  const auto [status, out] = pythonOn(
      a.out,
      "assert d['frames'] == 400, d['frames']\nassert d['nan_steps'] == 0, d\n"
      "assert d['max_penetration_m'] < 0.01, d\nassert abs(d['sim_time_s'] - 399 / 120.0) < 0.02, d\n"
      "k = d['kinetics'][0]\nassert abs(k['weight_n'] - 78.5 * 9.81) < 0.5, k\nprint('ok')");
  EXPECT_EQ(status, 0) << out << a.out;
}

TEST_F(SimulateTool, ShortDemoRunIsOneDeterministicJsonObjectWithFiniteNumbers) {
  const ToolResult a = run("--config configs/sim/sim_demo.yaml --duration 1 --json");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  // exactly one JSON object on stdout, on one line (python's json module reads it as a dict)
  ASSERT_FALSE(a.out.empty());
  EXPECT_EQ(a.out.front(), '{') << a.out;
  EXPECT_EQ(a.out.find('\n'), a.out.size() - 1) << a.out;
  const auto [py_status, py_out] = pythonOn(a.out, "assert isinstance(d, dict)\nprint('ok')");
  EXPECT_EQ(py_status, 0) << py_out;
  EXPECT_EQ(py_out, "ok\n");
  // the postures' ergonomic scores (libs/ergonomics) over the calibrated time: one entry per mannequin,
  // RULA 1..7 and REBA 1..15 at most, the time at the action levels summing to the sampled time
  const auto [e_status, e_out] = pythonOn(
      a.out,
      "e = d['ergonomics']\nassert len(e) == 1 and e[0]['mannequin'] == 'operator'\n"
      "assert 1 <= e[0]['rula_max'] <= 7 and 1 <= e[0]['reba_max'] <= 15\n"
      "assert len(e[0]['rula_time_at_action_level_s']) == 4 and len(e[0]['reba_time_at_action_level_s']) == 5\n"
      "t = sum(e[0]['rula_time_at_action_level_s'])\nassert abs(t - sum(e[0]['reba_time_at_action_level_s'])) < 1e-9\n"
      "assert abs(t - e[0]['samples'] / 60.0) < 1e-9 and 0.9 <= t <= 1.0 + 1e-9, t\nprint('ok')");
  EXPECT_EQ(e_status, 0) << e_out << a.out;
  for (const char* k : kKeys) {  // min_balance_distance_m included: the feet's floor contacts give a support
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
  // the signed distance of the CoM projection to the support boundary (3.22): a CoM over two feet is at
  // most half the feet's span (< 0.2 m) inside it, and the first second (standing, then the first
  // steps of the walk) never takes it as far as 0.3 m outside
  const double balance = *number(a.out, "min_balance_distance_m");
  EXPECT_LT(balance, 0.2) << a.out;
  EXPECT_GT(balance, -0.3) << a.out;

  const ToolResult b = run("--config configs/sim/sim_demo.yaml --duration 1 --json");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(withoutWallClock(a.out), withoutWallClock(b.out));
}

TEST_F(SimulateTool, OutFileHoldsSimWorldMessagesAtTheWorldRate) {
  const fs::path mcap = temp("run.mcap");
  const ToolResult r = run("--config configs/sim/sim_demo.yaml --duration 0.5 --out " + mcap.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
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

TEST_F(SimulateTool, OutFileCarriesTheSceneObjects) {
  // configs/scenes/table.yaml: the ball and the tray (movable, with a mass) rest on the table top
  // (z = 0.75 m); every sim.world carries them where the scene put them
  const fs::path mcap = temp("objects.mcap");
  const ToolResult r = run("--config configs/sim/sim_demo.yaml --scene configs/scenes/table.yaml --duration 0.3 --out " + mcap.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto messages = mannequin::recording::McapReader::open(mcap.string()).readAll();
  ASSERT_EQ(messages.size(), 18u);  // 0.3 s at 60 Hz
  for (const auto& m : messages) {
    mannequin::v1::WorldState w;
    ASSERT_TRUE(w.ParseFromString(m.data));
    ASSERT_EQ(w.objects_size(), 2) << w.ShortDebugString().substr(0, 500);
    for (const auto& o : w.objects()) {
      // ball centre = top + radius; tray centre = top + its 2 mm margin + half its 5 mm bottom; within the
      // contact layer's mm penetration tolerance, nothing sliding
      const bool ball = o.name() == "ball";
      ASSERT_TRUE(ball || o.name() == "tray") << o.name();
      const double x = ball ? 0.9 : 1.15, y = ball ? 0.2 : -0.15, z = ball ? 0.75 + 0.11 : 0.75 + 0.002 + 0.0025;
      EXPECT_NEAR(o.pose().position().z(), z, 2e-3) << o.name() << " at step " << w.step();
      EXPECT_NEAR(o.pose().position().x(), x, 1e-3) << o.name();
      EXPECT_NEAR(o.pose().position().y(), y, 1e-3) << o.name();
      EXPECT_LT(std::hypot(o.velocity().x(), o.velocity().y(), o.velocity().z()), 0.01) << o.name();
    }
  }
  fs::remove(mcap);
}

// --scenario: the jump scenario in the loop of the shipped demo, its timeline in the JSON summary; a bad
// scenario file: exit 2 naming the file and line, nothing on stdout.
TEST_F(SimulateTool, ScenarioRunReportsTheStatesEnteredAndABadScenarioNamesItsLine) {
  const ToolResult a = run("--scenario configs/scenarios/jump.yaml --json", 300);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto [status, out] = pythonOn(
      a.out,
      "s = d['scenario']\nassert s['name'] == 'jump' and s['states'] == 3, s\n"
      "assert [e['state'] for e in s['timeline']] == ['standing', 'airborne', 'landed'], s\n"
      "assert s['timeline'][1]['events'] == 'both feet off the floor', s\n"
      "assert s['timeline'][0]['t'] < s['timeline'][1]['t'] < s['timeline'][2]['t'] <= d['sim_time_s'], s\n"
      "assert s['final_state'] == 'landed' and s['unapplied_actions'] == 0, s\nprint('ok')");
  EXPECT_EQ(status, 0) << out << a.out;
  const fs::path bad = temp("bad_scenario.yaml");
  std::ofstream(bad) << "scenario: bad\nmannequins:\n  - {name: operator, frames: [hand_r]}\nstates:\n  - name: a\n"
                        "    transitions: [{to: nowhere, when: {time: 1}}]\n";
  const ToolResult r = run("--scenario " + bad.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":6"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}
