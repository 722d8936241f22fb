// mannequin-scenario as a process: --help, --graph on the shipped drill (SVG when Graphviz's dot is
// installed), --dot, the clear error without dot, a bad file's FILE:LINE.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common.hpp"

namespace fs = std::filesystem;

namespace {

// the tool lands in build/bin, the test binary in build/bin/tests
fs::path toolPath() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "mannequin-scenario"; }

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("scenario_tool_test_" + std::to_string(::getpid()) + "_" + name);
}

struct ToolRun {
  int status = -1;
  std::string out, err;
};

// runs under timeout(1) so a hang fails at the deadline; `env`: variables for the tool (e.g. "PATH=/x")
ToolRun run(const std::string& args, const std::string& env = "") {
  ToolRun r;
  const fs::path err = temp("stderr");
  const std::string cmd = "cd " + scenario_test::sourceDir() + " && timeout 60 " + (env.empty() ? "" : "env " + env + " ") + toolPath().string() + " " +
                          args + " 2>" + err.string();
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

std::string readFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool haveDot() { return std::system("command -v dot >/dev/null 2>&1") == 0; }

}  // namespace

TEST(ScenarioTool, Help) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  const ToolRun r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--graph"), std::string::npos);
  EXPECT_NE(r.out.find("--dot"), std::string::npos);
  EXPECT_EQ(run("").status, 2);  // nothing to do
  EXPECT_EQ(run("--graph configs/scenarios/drill.yaml").status, 2);  // no --out nor --dot
}

TEST(ScenarioTool, GraphOfTheDrillAsSvg) {
  if (!haveDot()) GTEST_SKIP() << "Graphviz 'dot' is not installed (Debian package graphviz, tools/setup)";
  const fs::path svg = temp("drill.svg");
  const ToolRun r = run("--graph configs/scenarios/drill.yaml --out " + svg.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = readFile(svg);
  fs::remove(svg);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  for (const char* state : {"approach", "drilling", "retract", "free"}) EXPECT_NE(text.find(state), std::string::npos) << state;
  EXPECT_NE(text.find("depth reached"), std::string::npos);
}

TEST(ScenarioTool, DotTextAndTheErrorWithoutDot) {
  const ToolRun dot = run("--graph configs/scenarios/interrupt.yaml --dot");
  ASSERT_EQ(dot.status, 0) << dot.err;
  EXPECT_EQ(dot.out.rfind("digraph \"interrupt\"", 0), 0u) << dot.out;
  EXPECT_NE(dot.out.find("__any -> s"), std::string::npos);  // the phone interrupt from any state
  EXPECT_NE(dot.out.find("-> __resume"), std::string::npos);
  // no dot on the PATH: exit 1 and a message naming the package and --dot
  const ToolRun none = run("--graph configs/scenarios/drill.yaml --out " + temp("x.svg").string(), "PATH=/nonexistent");
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("graphviz"), std::string::npos) << none.err;
  EXPECT_NE(none.err.find("--dot"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(temp("x.svg")));
}

TEST(ScenarioTool, BadFileNamesFileAndLine) {
  const fs::path bad = temp("bad.yaml");
  std::ofstream(bad) << "scenario: bad\nmannequins:\n  - {name: m, frames: [hand]}\nstates:\n  - name: a\n"
                        "    transitions:\n      - {to: b, when: {time: 1}}\n";
  const ToolRun r = run("--graph " + bad.string() + " --dot");
  fs::remove(bad);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(bad.string() + ":7:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unknown state 'b'"), std::string::npos) << r.err;
}
