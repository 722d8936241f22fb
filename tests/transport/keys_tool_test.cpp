// mannequin-keys run as a separate process: the files it writes, their modes, no overwrite, the
// public key of a secret file, and one-line errors with exit 2.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "../common/tool_run.hpp"
#include "mannequin/transport/security.hpp"

namespace fs = std::filesystem;
using namespace mannequin::transport;

namespace {

using mannequin::testutil::slurp;
using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-keys"; }

unsigned modeOf(const fs::path& p) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) return 0xFFFF;
  return st.st_mode & 07777;
}

class KeysTool : public mannequin::testutil::TempDirTest {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
    if (!hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
  }

  // under timeout(1): a hung tool fails the test at the deadline instead of hanging ctest
  ToolResult run(const std::string& args) { return mannequin::testutil::runTool(toolPath().string() + " " + args, 60); }
};

}  // namespace

TEST_F(KeysTool, GenerateWritesAPairWithASecretOfMode0600) {
  const ToolResult r = run("generate sim --dir " + dir_.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path pub = dir_ / "sim.key", sec = dir_ / "sim.key_secret";
  ASSERT_TRUE(fs::exists(pub));
  ASSERT_TRUE(fs::exists(sec));
  EXPECT_EQ(modeOf(sec), 0600u);
  EXPECT_EQ(modeOf(pub), 0644u);
  const std::string public_key = readKeyFile(pub.string(), false);
  const std::string secret_key = readKeyFile(sec.string(), true);
  EXPECT_EQ(curvePublicKey(secret_key), public_key);  // a real pair
  EXPECT_NE(r.out.find(public_key), std::string::npos) << r.out;
  // a second pair is another pair
  ASSERT_EQ(run("generate render1 --dir " + dir_.path().string()).exit_code, 0);
  EXPECT_NE(readKeyFile((dir_ / "render1.key").string(), false), public_key);
}

TEST_F(KeysTool, GenerateRefusesToOverwriteNamingTheFile) {
  ASSERT_EQ(run("generate sim --dir " + dir_.path().string()).exit_code, 0);
  const std::string secret_before = slurp(dir_ / "sim.key_secret"), public_before = slurp(dir_ / "sim.key");
  const ToolResult r = run("generate sim --dir " + dir_.path().string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find((dir_ / "sim.key").string() + ": already exists"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "sim.key_secret"), secret_before);
  EXPECT_EQ(slurp(dir_ / "sim.key"), public_before);
  // only the secret left over: still refused, and no public file written beside it
  fs::remove(dir_ / "sim.key");
  const ToolResult r2 = run("generate sim --dir " + dir_.path().string());
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find((dir_ / "sim.key_secret").string() + ": already exists"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(dir_ / "sim.key"));
}

TEST_F(KeysTool, PublicPrintsThePublicKeyOfASecretFile) {
  ASSERT_EQ(run("generate mocap --dir " + dir_.path().string()).exit_code, 0);
  const ToolResult r = run("public " + (dir_ / "mocap.key_secret").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, readKeyFile((dir_ / "mocap.key").string(), false) + "\n");
}

TEST_F(KeysTool, BadInputIsOneLineAndExit2) {
  auto oneLine = [](const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; };
  ToolResult r = run("public " + (dir_ / "none.key_secret").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(oneLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("none.key_secret"), std::string::npos) << r.err;

  std::ofstream(dir_ / "bad.key_secret") << "garbage\n";
  fs::permissions(dir_ / "bad.key_secret", fs::perms::owner_read | fs::perms::owner_write);
  r = run("public " + (dir_ / "bad.key_secret").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(oneLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("bad.key_secret:1: not a Z85 CURVE key"), std::string::npos) << r.err;

  ASSERT_EQ(run("generate open --dir " + dir_.path().string()).exit_code, 0);
  fs::permissions(dir_ / "open.key_secret", fs::perms::others_read, fs::perm_options::add);
  r = run("public " + (dir_ / "open.key_secret").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("readable by others"), std::string::npos) << r.err;

  r = run("generate ../escape --dir " + dir_.path().string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(oneLine(r.err)) << r.err;
  r = run("generate x --dir " + (dir_ / "no-such-dir").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no-such-dir"), std::string::npos) << r.err;
  r = run("frobnicate");
  EXPECT_EQ(r.exit_code, 2);
  r = run("");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(run("--help").exit_code, 0);
}
