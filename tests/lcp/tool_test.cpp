// mannequin-lcp run as a separate process: statuses, the line of a malformed file, exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {
// the tool lands in build/bin, the test binary in build/bin/tests
fs::path toolPath() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "mannequin-lcp"; }

struct ToolRun {
  int status = -1;
  std::string out;
};

ToolRun run(const std::string& args) {
  ToolRun r;
  FILE* p = ::popen((toolPath().string() + " " + args + " 2>/dev/null").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string example(const std::string& name) {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return std::string(root ? root : ".") + "/tools/lcp/examples/" + name;
}

fs::path writeTemp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("lcp_tool_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(LcpTool, SolvesTheShippedExampleAsJson) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  for (const char* solver : {"lemke", "pgs", "structured"}) {
    const ToolRun r = run("solve " + example("murty.lcp") + " --solver " + solver + " --json");
    EXPECT_EQ(r.status, 0) << solver << ": " << r.out;
    EXPECT_NE(r.out.find("\"status\": \"solved\""), std::string::npos) << solver << ": " << r.out;
  }
}

TEST(LcpTool, InfeasibleProblemIsNoSolution) {
  const ToolRun r = run("solve " + example("infeasible.lcp") + " --json");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"no_solution\""), std::string::npos) << r.out;
}

TEST(LcpTool, MalformedFileIsInvalidWithItsLineAndExitCode2) {
  // line 4 holds a word where the second row of M should be
  const fs::path bad = writeTemp("bad.lcp", "# comment\n2\n1 0\n0 x\n-1 -1\n");
  ToolRun r = run("solve " + bad.string() + " --json");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"invalid\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line 4"), std::string::npos) << r.out;
  // too few numbers: the file ends before q is complete
  const fs::path cut = writeTemp("cut.lcp", "2\n1 0\n0 1\n-1\n");
  r = run("solve " + cut.string() + " --json");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"invalid\""), std::string::npos) << r.out;
  // NaN entries
  const fs::path nan = writeTemp("nan.lcp", "1\nnan\n-1\n");
  r = run("solve " + nan.string() + " --json");
  EXPECT_EQ(r.status, 2) << r.out;
  fs::remove(bad);
  fs::remove(cut);
  fs::remove(nan);
}

TEST(LcpTool, BadCommandLineExitsWith2) {
  EXPECT_EQ(run("solve " + example("murty.lcp") + " --solver simplex").status, 2);
  EXPECT_EQ(run("frobnicate").status, 2);
  EXPECT_EQ(run("solve /nonexistent/file.lcp --json").status, 2);
}
