// mannequin-lcp run as a separate process: statuses, the line of a malformed file, exit codes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "../common/tool_run.hpp"

namespace fs = std::filesystem;

namespace {
using mannequin::testutil::binDir;
using mannequin::testutil::ToolResult;

fs::path toolPath() { return binDir() / "mannequin-lcp"; }

// stderr is not looked at: the JSON on stdout carries the status
ToolResult run(const std::string& args) { return mannequin::testutil::runTool(toolPath().string() + " " + args, 60); }

std::string example(const std::string& name) {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return std::string(root ? root : ".") + "/tools/lcp/examples/" + name;
}

fs::path writeTemp(const mannequin::testutil::TempDir& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(LcpTool, SolvesTheShippedExampleAsJson) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  for (const char* solver : {"lemke", "pgs", "structured"}) {
    const ToolResult r = run("solve " + example("murty.lcp") + " --solver " + solver + " --json");
    EXPECT_EQ(r.exit_code, 0) << solver << ": " << r.out;
    EXPECT_NE(r.out.find("\"status\": \"solved\""), std::string::npos) << solver << ": " << r.out;
  }
}

TEST(LcpTool, InfeasibleProblemIsNoSolution) {
  const ToolResult r = run("solve " + example("infeasible.lcp") + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"no_solution\""), std::string::npos) << r.out;
}

TEST(LcpTool, MalformedFileIsInvalidWithItsLineAndExitCode2) {
  // line 4 holds a word where the second row of M should be
  const mannequin::testutil::TempDir tmp("lcp_tool_test");
  const fs::path bad = writeTemp(tmp, "bad.lcp", "# comment\n2\n1 0\n0 x\n-1 -1\n");
  ToolResult r = run("solve " + bad.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"invalid\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line 4"), std::string::npos) << r.out;
  // too few numbers: the file ends before q is complete
  const fs::path cut = writeTemp(tmp, "cut.lcp", "2\n1 0\n0 1\n-1\n");
  r = run("solve " + cut.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"invalid\""), std::string::npos) << r.out;
  // NaN entries
  const fs::path nan = writeTemp(tmp, "nan.lcp", "1\nnan\n-1\n");
  r = run("solve " + nan.string() + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  fs::remove(bad);
  fs::remove(cut);
  fs::remove(nan);
}

TEST(LcpTool, BadCommandLineExitsWith2) {
  EXPECT_EQ(run("solve " + example("murty.lcp") + " --solver simplex").exit_code, 2);
  EXPECT_EQ(run("frobnicate").exit_code, 2);
  EXPECT_EQ(run("solve /nonexistent/file.lcp --json").exit_code, 2);
}
