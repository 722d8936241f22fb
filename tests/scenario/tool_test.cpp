// mannequin-scenario as a process: --help, --graph on the shipped drill (SVG when Graphviz's dot is
// installed), --dot, the clear error without dot, a bad file's FILE:LINE.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "../common/tool_run.hpp"
#include "common.hpp"

namespace fs = std::filesystem;

namespace {

using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-scenario"; }

// runs in the checkout under timeout(1) so a hang fails at the deadline; `env`: variables for the tool
// (e.g. "PATH=/x")
ToolResult run(const std::string& args, const std::string& env = "") {
  return mannequin::testutil::runTool((env.empty() ? "" : "env " + env + " ") + toolPath().string() + " " + args, 60,
                                      scenario_test::sourceDir());
}

bool haveDot() { return std::system("command -v dot >/dev/null 2>&1") == 0; }

// Each test's files (temp(name)) in a directory of its own, removed after it.
using ScenarioTool = mannequin::testutil::TempDirTest;

}  // namespace

TEST_F(ScenarioTool, Help) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  const ToolResult r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--graph"), std::string::npos);
  EXPECT_NE(r.out.find("--dot"), std::string::npos);
  EXPECT_EQ(run("").exit_code, 2);  // nothing to do
  EXPECT_EQ(run("--graph configs/scenarios/drill.yaml").exit_code, 2);  // no --out nor --dot
}

TEST_F(ScenarioTool, GraphOfTheDrillAsSvg) {
  if (!haveDot()) GTEST_SKIP() << "Graphviz 'dot' is not installed (Debian package graphviz, tools/setup)";
  const fs::path svg = temp("drill.svg");
  const ToolResult r = run("--graph configs/scenarios/drill.yaml --out " + svg.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = mannequin::testutil::slurp(svg);
  fs::remove(svg);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  for (const char* state : {"approach", "drilling", "retract", "free"}) EXPECT_NE(text.find(state), std::string::npos) << state;
  EXPECT_NE(text.find("depth reached"), std::string::npos);
}

TEST_F(ScenarioTool, DotTextAndTheErrorWithoutDot) {
  const ToolResult dot = run("--graph configs/scenarios/interrupt.yaml --dot");
  ASSERT_EQ(dot.exit_code, 0) << dot.err;
  EXPECT_EQ(dot.out.rfind("digraph \"interrupt\"", 0), 0u) << dot.out;
  EXPECT_NE(dot.out.find("__any -> s"), std::string::npos);  // the phone interrupt from any state
  EXPECT_NE(dot.out.find("-> __resume"), std::string::npos);
  // no dot on the PATH: exit 1 and a message naming the package and --dot
  const ToolResult none = run("--graph configs/scenarios/drill.yaml --out " + temp("x.svg").string(), "PATH=/nonexistent");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("graphviz"), std::string::npos) << none.err;
  EXPECT_NE(none.err.find("--dot"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(temp("x.svg")));
}

TEST_F(ScenarioTool, BadFileNamesFileAndLine) {
  const fs::path bad = temp("bad.yaml");
  std::ofstream(bad) << "scenario: bad\nmannequins:\n  - {name: m, frames: [hand]}\nstates:\n  - name: a\n"
                        "    transitions:\n      - {to: b, when: {time: 1}}\n";
  const ToolResult r = run("--graph " + bad.string() + " --dot");
  fs::remove(bad);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(bad.string() + ":7:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unknown state 'b'"), std::string::npos) << r.err;
}
