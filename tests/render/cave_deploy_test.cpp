// configs/deployments/cave.yaml: the single-host CAVE rehearsal (mocap, collision, sim and three synchronised
// headless walls) started by mannequin-launch: the three walls swap the same sim.world steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "../common/tool_run.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/render/view.hpp"

namespace fs = std::filesystem;

namespace mannequin::render {
namespace {

using testutil::binDir;
using testutil::slurp;

// One swap per line of DIR/swaps.log: "step steady_ns".
std::vector<std::pair<std::uint64_t, std::int64_t>> swaps(const fs::path& dir) {
  std::vector<std::pair<std::uint64_t, std::int64_t>> out;
  std::ifstream in(dir / "swaps.log");
  std::uint64_t step;
  std::int64_t t;
  while (in >> step >> t) out.emplace_back(step, t);
  return out;
}

const char* const kWalls[] = {"wall_front", "wall_left", "wall_right"};

TEST(CaveDeployment, TheWallViewsAreTheShippedWallsWithTheSwapBarrier) {
  for (const char* wall : kWalls) {
    const ViewConfig cave = loadView(core::findData(std::string("configs/deployments/cave/") + wall + ".yaml"));
    const ViewConfig shipped = loadView(core::findData(std::string("configs/views/") + wall + ".yaml"));
    EXPECT_TRUE(cave.sync) << wall;
    EXPECT_EQ(cave.type, ViewConfig::Type::kWall) << wall;
    EXPECT_EQ(cave.wall.lower_left, shipped.wall.lower_left) << wall;
    EXPECT_EQ(cave.wall.lower_right, shipped.wall.lower_right) << wall;
    EXPECT_EQ(cave.wall.upper_left, shipped.wall.upper_left) << wall;
    EXPECT_EQ(cave.head, shipped.head) << wall;
  }
}

TEST(CaveDeployment, TheCaveRehearsalSwapsTheSameStepsOnTheThreeWalls) {
  const fs::path file = fs::absolute(core::findData("configs/deployments/cave.yaml"));
  const fs::path checkout = file.parent_path().parent_path().parent_path();  // the services read configs/ from here
  const testutil::TempDir tmp("cave_deploy_test");
  const fs::path run_dir = tmp / "run", summary = tmp / "summary.json";
  const std::string cmd = (binDir() / "mannequin-launch").string() + " " + file.string() + " --duration 10 --run-dir " +
                          run_dir.string() + " --no-tty --summary-json " + summary.string();
  const testutil::ToolResult st = testutil::runTool(cmd, 120, checkout.string());
  ASSERT_NE(st.exit_code, -1) << cmd;
  EXPECT_EQ(st.exit_code, 0) << cmd;
  const std::string json = slurp(summary);
  for (const char* wall : kWalls) {  // each wall ran once, heartbeating, without a restart
    const auto at = json.find(std::string("\"name\": \"") + wall + "\"");
    ASSERT_NE(at, std::string::npos) << json;
    const auto hb = json.find("\"heartbeats\": ", at);
    ASSERT_NE(hb, std::string::npos) << json;
    EXPECT_GT(std::stol(json.substr(hb + 14)), 0) << wall << "\n" << json;
    const auto restarts = json.find("\"restarts\": ", at);
    ASSERT_NE(restarts, std::string::npos) << json;
    EXPECT_EQ(std::stol(json.substr(restarts + 12)), 0) << wall << "\n" << json;
  }
  std::vector<std::vector<std::pair<std::uint64_t, std::int64_t>>> logs;
  for (const char* wall : kWalls) {
    const fs::path dir = run_dir / "frames" / wall;
    logs.push_back(swaps(dir));
    const auto& v = logs.back();
    ASSERT_GE(v.size(), 10u) << wall << " swapped " << v.size() << " frames in 10 s (" << (dir / "swaps.log") << ")";
    for (std::size_t i = 1; i < v.size(); ++i) EXPECT_LT(v[i - 1].first, v[i].first) << wall << ": steps go forward";
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(v.back().first));
    EXPECT_TRUE(fs::exists(dir / name)) << dir / name;
  }
  // over the range all three ran (a node may start or stop a frame apart from the others), the same steps
  std::uint64_t first = 0, last = UINT64_MAX;
  for (const auto& v : logs) {
    first = std::max(first, v.front().first);
    last = std::min(last, v.back().first);
  }
  std::vector<std::vector<std::uint64_t>> steps(logs.size());
  for (std::size_t i = 0; i < logs.size(); ++i)
    for (const auto& [step, t] : logs[i])
      if (step >= first && step <= last) steps[i].push_back(step);
  EXPECT_GE(steps[0].size(), 8u);
  EXPECT_EQ(steps[0], steps[1]) << "wall_front and wall_left swapped different steps";
  EXPECT_EQ(steps[0], steps[2]) << "wall_front and wall_right swapped different steps";
  fs::remove(summary);
  fs::remove_all(run_dir);
}

}  // namespace
}  // namespace mannequin::render
