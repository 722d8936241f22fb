// runMain: the exit codes every executable promises (help 0, bad command line 2, a throwing body 1
// with the error logged), and the body's own code passed through.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/core/config.hpp"
#include "mannequin/core/main.hpp"

namespace {
using namespace mannequin::core;

int run(std::vector<std::string> args, const std::function<int()>& body, int* value = nullptr) {
  CLI::App app{"test"};
  int v = 0;
  app.add_option("--value", v, "a number")->check(CLI::Range(0, 10));
  args.insert(args.begin(), "prog");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  const int rc = runMain(app, static_cast<int>(argv.size()), argv.data(), body);
  if (value) *value = v;
  return rc;
}

TEST(RunMain, PassesTheBodysCodeAndTheParsedOptions) {
  int v = -1;
  bool ran = false;
  EXPECT_EQ(run({"--value", "7"}, [&] { ran = true; return 0; }, &v), kExitOk);
  EXPECT_TRUE(ran);
  EXPECT_EQ(v, 7);
  EXPECT_EQ(run({}, [] { return 1; }), 1);
}

TEST(RunMain, HelpIsZeroAndBadUseIsTwoWithoutRunningTheBody) {
  bool ran = false;
  auto body = [&] { ran = true; return 0; };
  EXPECT_EQ(run({"--help"}, body), kExitOk);
  EXPECT_EQ(run({"--value", "11"}, body), kExitUsage);   // out of range
  EXPECT_EQ(run({"--value", "x"}, body), kExitUsage);    // not a number
  EXPECT_EQ(run({"--frobnicate"}, body), kExitUsage);    // unknown option
  EXPECT_EQ(run({"extra"}, body), kExitUsage);           // unexpected positional
  EXPECT_FALSE(ran);
}

TEST(RunMain, AThrowingBodyIsLoggedAndExitsOneNeverTerminates) {
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  const int a = run({}, []() -> int { throw ConfigError("cfg.yaml:3: field 'x': bad"); });
  const int b = run({}, []() -> int { throw std::runtime_error("disk on fire"); });
  const int c = run({}, []() -> int { throw 42; });
  const std::string out = testing::internal::GetCapturedStdout() + testing::internal::GetCapturedStderr();
  EXPECT_EQ(a, kExitFailure);
  EXPECT_EQ(b, kExitFailure);
  EXPECT_EQ(c, kExitFailure);
  EXPECT_NE(out.find("cfg.yaml:3: field 'x': bad"), std::string::npos) << out;
  EXPECT_NE(out.find("disk on fire"), std::string::npos) << out;
  EXPECT_NE(out.find("critical"), std::string::npos) << out;
}

TEST(SetupLogging, RefusesAnUnknownLevel) {
  EXPECT_NO_THROW(setupLogging("debug"));
  EXPECT_THROW(setupLogging("loud"), std::invalid_argument);
  setupLogging("info");
}

}  // namespace

namespace {
using namespace mannequin::core;

TEST(RunMain, AParseErrorFromTheBodyIsBadUse) {
  CLI::App app{"test"};
  EXPECT_EQ(runMain(app, std::vector<std::string>{}, []() -> int { throw CLI::ValidationError("--a needs --b"); }), kExitUsage);
}

TEST(RunMain, TakesArgumentsAsAVectorInOrder) {
  CLI::App app{"test"};
  std::vector<std::string> got;
  app.add_option("words", got, "words");
  EXPECT_EQ(runMain(app, {"a", "b", "c"}, [] { return 0; }), kExitOk);
  EXPECT_EQ(got, (std::vector<std::string>{"a", "b", "c"}));
}

}  // namespace
