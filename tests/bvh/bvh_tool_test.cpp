// mannequin-bvh run as a separate process: exact --json outputs and exit codes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "bvh_data.hpp"
#include "../common/tool_run.hpp"

namespace fs = std::filesystem;

namespace {

using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-bvh"; }


class ToolTest : public mannequin::testutil::TempDirTest {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  }

  // runs the tool with `args` (already shell-quoted where needed) under a 60 s deadline
  ToolResult run(const std::string& args) { return mannequin::testutil::runTool(toolPath().string() + " " + args, 60); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

};

// a small capture whose joint names carry a namespace prefix ("b:B")
const char* kTinyPrefixed =
    "HIERARCHY\nROOT A\n{\n  OFFSET 1 2 3\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT b:B\n  {\n    OFFSET 0 1 0\n    CHANNELS 3 Xrotation Yrotation Zrotation\n"
    "    End Site\n    {\n      OFFSET 0 0 2\n    }\n  }\n}\n"
    "MOTION\nFrames: 2\nFrame Time: 0.5\n10 0 0 90 0 0 0 0 0\n0 0 0 0 0 0 90 0 0\n";

}  // namespace

TEST_F(ToolTest, InfoJsonOnRealCaptures) {
  ToolResult r = run("info " + mannequin::testing::bvhDataPath("cmu_max_131_03.bvh") + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "{\"joints\": 31, \"channels\": 96, \"frames\": 1102, \"frame_time\": 0.0083333, \"root\": \"Hips\"}\n");
  r = run("info --json " + mannequin::testing::bvhDataPath("mocapbank_test.bvh"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "{\"joints\": 19, \"channels\": 60, \"frames\": 455, \"frame_time\": 0.033333, \"root\": \"Hips\"}\n");
}

TEST_F(ToolTest, InfoHumanReadable) {
  const ToolResult r = run("info " + write("tiny.bvh", kTinyPrefixed));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("joints:     2 (+ 1 End Sites)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("b:B  offset (0, 1, 0)  [Xrotation Yrotation Zrotation]"), std::string::npos) << r.out;
}

TEST_F(ToolTest, PosesJsonExact) {
  // hand-computed: frame 0 turns the root 90° about z, frame 1 the child 90° about x; End Sites omitted
  const ToolResult r = run("poses " + write("tiny.bvh", kTinyPrefixed) + " --frames 0,-1 --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out,
            "{\"0\": {\"A\": {\"p\": [11, 2, 3], \"R\": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}, "
            "\"b:B\": {\"p\": [10, 2, 3], \"R\": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}}, "
            "\"1\": {\"A\": {\"p\": [1, 2, 3], \"R\": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, "
            "\"b:B\": {\"p\": [1, 3, 3], \"R\": [[1, 0, 0], [0, 0, -1], [0, 1, 0]]}}}\n");
  // a lone negative frame, repeated frames printed once under the resolved key
  const ToolResult last = run("poses " + write("tiny2.bvh", kTinyPrefixed) + " --frames -1 --json");
  const ToolResult again = run("poses " + write("tiny3.bvh", kTinyPrefixed) + " --frames=1,-1 --json");
  EXPECT_EQ(last.exit_code, 0) << last.err;
  EXPECT_EQ(last.out.rfind("{\"1\": {\"A\": {\"p\": [1, 2, 3]", 0), 0u) << last.out;
  EXPECT_EQ(last.out, again.out);
}

TEST_F(ToolTest, PosesJsonOnRealCapture) {
  const ToolResult r = run("poses " + mannequin::testing::bvhDataPath("cmu_max_131_03.bvh") + " --frames 0,100,-1 --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // the root is at offset (0,0,0) + the position channels of frame 0 (5.1723 16.9371 -29.1264)
  EXPECT_EQ(r.out.rfind("{\"0\": {\"Hips\": {\"p\": [5.1723, 16.9371, -29.1264], \"R\": [[", 0), 0u) << r.out.substr(0, 200);
  EXPECT_NE(r.out.find("}, \"100\": {\"Hips\": "), std::string::npos);
  EXPECT_NE(r.out.find("}, \"1101\": {\"Hips\": {\"p\": [2.9281, 15.8841, 28.7282]"), std::string::npos);
  // 31 named joints per frame, 3 frames
  std::size_t count = 0;
  for (std::size_t pos = 0; (pos = r.out.find("\"p\": [", pos)) != std::string::npos; ++pos) ++count;
  EXPECT_EQ(count, 3u * 31u);
  EXPECT_EQ(r.out.find("End"), std::string::npos);
}

TEST_F(ToolTest, BadCommandLinesExitTwo) {
  const std::string tiny = write("tiny.bvh", kTinyPrefixed);
  const struct {
    std::string args;
    const char* message;
  } cases[] = {
      {"", "A subcommand is required"},
      {"info", "FILE is required"},
      {"poses " + tiny, "--frames is required"},
      {"poses " + tiny + " --frames 2", "--frames: frame 2 is out of range (the motion has 2 frames: 0..1 or -2..-1)"},
      {"poses " + tiny + " --frames -3", "--frames: frame -3 is out of range"},
      {"poses " + tiny + " --frames 0,x", "--frames: expected a comma-separated list of integers, got 'x'"},
      {"poses " + tiny + " --frames 0,,1", "--frames: expected a comma-separated list of integers, got ''"},
      {"info " + tiny + " --bogus", "--bogus"},
  };
  for (const auto& c : cases) {
    const ToolResult r = run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_TRUE(r.out.empty()) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << " -> " << r.err;
  }
  const ToolResult help = run("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("RESOLVED non-negative index"), std::string::npos);
}

TEST_F(ToolTest, MalformedFileExitsOneWithFileAndLine) {
  std::string broken = kTinyPrefixed;
  broken.replace(broken.find("0 0 0 0 0 0 90 0 0"), 18, "0 0 0 0 0 0 90 0");
  const std::string path = write("broken.bvh", broken);
  const ToolResult r = run("info " + path + " --json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(r.err, "mannequin-bvh: " + path + ":20: expected 9 channel values in frame 1, got 8\n");
  const ToolResult missing = run("info " + (dir_ / "none.bvh").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.bvh: cannot open file"), std::string::npos);
}
