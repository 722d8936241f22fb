// The checked signal: a pid ≤ 0 is refused without calling kill() (kill(-1) as root signals nearly every
// process on the machine, kill(0) the caller's own group).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include "mannequin/core/process.hpp"

namespace {
using mannequin::core::processGone;
using mannequin::core::SignalResult;
using mannequin::core::signalProcess;
using mannequin::core::SignalTarget;

TEST(SignalProcess, RefusesPidsThatNameMoreThanOneProcess) {
  // signal 0 only checks permission, so even if the guard failed nothing would be killed
  EXPECT_EQ(signalProcess(-1, 0), SignalResult::kRefused);
  EXPECT_EQ(signalProcess(0, 0), SignalResult::kRefused);
  EXPECT_EQ(signalProcess(-1234, 0), SignalResult::kRefused);
  EXPECT_EQ(signalProcess(0, 0, SignalTarget::kGroup), SignalResult::kRefused);
  EXPECT_EQ(signalProcess(1, 0, SignalTarget::kGroup), SignalResult::kRefused);  // kill(-1)
  EXPECT_FALSE(processGone(-1));
  EXPECT_FALSE(processGone(0));
}

TEST(SignalProcess, SignalsARealChildAndSeesItGone) {
  const pid_t child = fork();
  ASSERT_GE(child, 0) << "fork failed";
  if (child == 0) {
    pause();
    _exit(0);
  }
  EXPECT_EQ(signalProcess(child, SIGKILL), SignalResult::kSent);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  EXPECT_TRUE(processGone(child));
  EXPECT_EQ(signalProcess(child, SIGKILL), SignalResult::kNoProcess);
}

TEST(SignalProcess, SignalsAProcessGroup) {
  const pid_t child = fork();
  ASSERT_GE(child, 0) << "fork failed";
  if (child == 0) {
    setpgid(0, 0);
    pause();
    _exit(0);
  }
  setpgid(child, child);  // both sides, so the group exists whichever runs first
  EXPECT_EQ(signalProcess(child, SIGTERM, SignalTarget::kGroup), SignalResult::kSent);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
}

}  // namespace
