// mannequin-retarget run as a process: a readable BVH out, the levels reported, bad input's exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "mannequin/skeleton/bvh.hpp"

namespace mannequin::ik {
namespace {

int run(const std::string& args) {
  const int status = std::system((std::string(MANNEQUIN_BIN_DIR) + "/mannequin-retarget " + args + " > /tmp/mannequin-retarget-test.log 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(RetargetTool, WritesAReadableBvhAndReportsLevels) {
  const std::string out = ::testing::TempDir() + "retarget_out.bvh";
  ASSERT_EQ(run("data/bvh/cmu_max_131_03.bvh --mannequin configs/mannequins/female_05th.yaml --end 40 --out " + out), 0);
  const skeleton::Bvh bvh = skeleton::readBvhFile(out);
  EXPECT_EQ(bvh.num_frames, 40);
  EXPECT_EQ(skeleton::bvhJointCount(bvh), 24);
  std::ifstream log("/tmp/mannequin-retarget-test.log");
  const std::string text((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(text.find("feet"), std::string::npos);
  EXPECT_NE(text.find("hands"), std::string::npos);
  // bad input: missing file and bad options exit 2 (command line), a bad mannequin config 1
  EXPECT_EQ(run("no_such.bvh --out " + out), 2);
  EXPECT_EQ(run("data/bvh/cmu_max_131_03.bvh --out " + out + " --calibration tpose"), 2);
  EXPECT_EQ(run("data/bvh/cmu_max_131_03.bvh --out " + out + " --start 5 --end 5"), 1);
  EXPECT_EQ(run("data/bvh/cmu_max_131_03.bvh --mannequin data/README.md --out " + out), 1);
}

// cgspeed's MotionBuilder conversions start with a T-pose (data/README.md): without --start it is skipped, so the
// calibration ('first') takes the actor standing
TEST(RetargetTool, SkipsTheConvertersTPoseUnlessAStartIsGiven) {
  const std::string out = ::testing::TempDir() + "retarget_tpose.bvh";
  ASSERT_EQ(run("data/bvh/cmu_115_02.bvh --map configs/mappings/cmu_mb.yaml --end 6 --out " + out), 0);
  EXPECT_EQ(skeleton::readBvhFile(out).num_frames, 5);  // frames 1..5
  std::ifstream log("/tmp/mannequin-retarget-test.log");
  const std::string text((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(text.find("cmu_115_02.bvh: frame 0 is a T-pose"), std::string::npos) << text;
  ASSERT_EQ(run("data/bvh/cmu_115_02.bvh --map configs/mappings/cmu_mb.yaml --start 0 --end 6 --out " + out), 0);
  EXPECT_EQ(skeleton::readBvhFile(out).num_frames, 6);  // asked for: frames 0..5
}

}  // namespace
}  // namespace mannequin::ik
