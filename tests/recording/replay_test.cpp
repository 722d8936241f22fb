// ReplayClock timing math and the Player driven by a scripted clock (no real sleeping).
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <filesystem>
#include <stdexcept>

#include "mannequin/recording/mcap_writer.hpp"
#include "mannequin/recording/replay.hpp"
#include "test_files.hpp"

using namespace mannequin::recording;
using namespace mannequin::recording::testing;

namespace {

constexpr WallTime kW0 = 5'000'000'000;  // arbitrary wall origin

TEST(ReplayClock, OriginalTimingAndRate) {
  ReplayClock c(1.0);
  c.start(1'000'000'000, kW0);
  EXPECT_EQ(c.due(1'000'000'000), kW0);
  EXPECT_EQ(c.due(1'250'000'000), kW0 + 250'000'000);
  EXPECT_EQ(c.recordingTime(kW0 + 100), 1'000'000'100U);

  ReplayClock fast(4.0);
  fast.start(1'000'000'000, kW0);
  EXPECT_EQ(fast.due(1'400'000'000), kW0 + 100'000'000);  // 0.4 s at 4x = 0.1 s
  EXPECT_EQ(fast.recordingTime(kW0 + 100'000'000), 1'400'000'000U);

  ReplayClock slow(0.5);
  slow.start(0, kW0);
  EXPECT_EQ(slow.due(3), kW0 + 6);
  EXPECT_THROW(ReplayClock(0.0), std::invalid_argument);
  EXPECT_THROW(ReplayClock(-1.0), std::invalid_argument);
  EXPECT_THROW(ReplayClock(std::nan("")), std::invalid_argument);
}

TEST(ReplayClock, PauseDoesNotCountAndRateChangeIsContinuous) {
  ReplayClock c(2.0);
  c.start(0, kW0);
  c.pause(kW0 + 100);  // recording time 200
  EXPECT_TRUE(c.paused());
  EXPECT_EQ(c.due(300), kNever);
  EXPECT_EQ(c.recordingTime(kW0 + 10'000), 200U);
  c.resume(kW0 + 1'000);  // 900 ns of pause
  EXPECT_EQ(c.due(300), kW0 + 1'000 + 50);
  c.setRate(1.0, kW0 + 1'050);  // recording time 300 at that instant
  EXPECT_EQ(c.recordingTime(kW0 + 1'050), 300U);
  EXPECT_EQ(c.due(400), kW0 + 1'150);
  // step while paused moves the frozen time forward, never back
  c.pause(kW0 + 1'150);
  c.stepTo(450);
  c.stepTo(420);
  EXPECT_EQ(c.recordingTime(kW0 + 99'999), 450U);
  c.resume(kW0 + 2'000);
  EXPECT_EQ(c.due(460), kW0 + 2'010);
}

// Scripted control: time jumps to each deadline; commands fire at given wall times.
class FakeControl : public ReplayControl {
 public:
  explicit FakeControl(WallTime t0) : now_(t0) {}
  WallTime now() override { return now_; }
  PlayerCommand waitUntil(WallTime deadline) override {
    ++waits;
    if (!script_.empty() && script_.front().first <= deadline) {
      now_ = std::max(now_, script_.front().first);
      const PlayerCommand c = script_.front().second;
      script_.pop_front();
      return c;
    }
    if (deadline == kNever) throw std::logic_error("waiting forever with nothing scripted");
    now_ = std::max(now_, deadline);
    return PlayerCommand::kNone;
  }
  void at(WallTime t, PlayerCommand c) { script_.emplace_back(t, c); }
  int waits = 0;

 private:
  WallTime now_;
  std::deque<std::pair<WallTime, PlayerCommand>> script_;
};

struct Published {
  WallTime at;
  std::uint32_t sequence;
  std::string topic;
};

class PlayerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = tempPath("player.mcap");
    McapWriterOptions o;
    o.chunk_size = 256;  // several chunks
    McapWriter w(path_.string(), o);
    sent_ = writeStream(w, 40);  // log times 1 s + i ms
    w.close();
    reader_.emplace(McapReader::open(path_.string()));
  }
  void TearDown() override { std::filesystem::remove(path_); }

  std::vector<Published> play(PlayerOptions o, FakeControl& control, PlayerStats* stats = nullptr) {
    std::vector<Published> out;
    Player p(*reader_, o);
    const PlayerStats s = p.run(control, [&](const Message& m, const Channel& c) {
      out.push_back({control.now(), m.sequence, c.topic});
    });
    if (stats != nullptr) *stats = s;
    return out;
  }

  std::filesystem::path path_;
  std::vector<Sent> sent_;
  std::optional<McapReader> reader_;
};

TEST_F(PlayerTest, OriginalTimingPublishesAtTheRecordedOffsets) {
  FakeControl control(kW0);
  PlayerStats stats;
  const auto out = play({}, control, &stats);
  ASSERT_EQ(out.size(), 40U);
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].sequence, i);
    EXPECT_EQ(out[i].at, kW0 + static_cast<WallTime>(i) * 1'000'000) << i;  // 1 ms apart, exactly
  }
  EXPECT_EQ(stats.published, 40U);
  EXPECT_EQ(stats.passes, 1U);
  EXPECT_FALSE(stats.quit);
}

TEST_F(PlayerTest, RateFactorStartEndAndTopics) {
  FakeControl control(kW0);
  PlayerOptions o;
  o.rate = 2.5;
  o.filter.start = 1'000'000'000ULL + 10'000'000ULL;  // from message 10
  o.filter.end = 1'000'000'000ULL + 29'000'000ULL;    // to message 29
  o.filter.topics = {"/a"};                           // even sequences
  const auto out = play(o, control);
  ASSERT_EQ(out.size(), 10U);
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_EQ(out[k].sequence, 10 + 2 * k);
    EXPECT_EQ(out[k].topic, "/a");
    EXPECT_EQ(out[k].at, kW0 + static_cast<WallTime>(2 * k) * 400'000) << k;  // 2 ms / 2.5
  }
}

TEST_F(PlayerTest, LoopRestartsRightAfterTheLastMessage) {
  FakeControl control(kW0);
  PlayerOptions o;
  o.loop = true;
  o.max_loops = 3;
  PlayerStats stats;
  const auto out = play(o, control, &stats);
  ASSERT_EQ(out.size(), 120U);
  EXPECT_EQ(stats.passes, 3U);
  EXPECT_EQ(out[40].sequence, 0U);
  EXPECT_EQ(out[40].at, out[39].at);  // next pass starts at once
  EXPECT_EQ(out[119].at, kW0 + 3 * 39'000'000);
}

TEST_F(PlayerTest, PauseStepResumeQuit) {
  FakeControl control(kW0);
  // pause at 5.5 ms (after message 5), step twice, resume at 100 ms, quit at 110 ms
  control.at(kW0 + 5'500'000, PlayerCommand::kTogglePause);
  control.at(kW0 + 50'000'000, PlayerCommand::kStep);
  control.at(kW0 + 60'000'000, PlayerCommand::kStep);
  control.at(kW0 + 100'000'000, PlayerCommand::kTogglePause);
  control.at(kW0 + 110'000'000, PlayerCommand::kQuit);
  PlayerStats stats;
  const auto out = play({}, control, &stats);
  EXPECT_TRUE(stats.quit);
  ASSERT_GE(out.size(), 8U);
  EXPECT_EQ(out[5].at, kW0 + 5'000'000);
  EXPECT_EQ(out[6].sequence, 6U);
  EXPECT_EQ(out[6].at, kW0 + 50'000'000);  // stepped
  EXPECT_EQ(out[7].at, kW0 + 60'000'000);  // stepped
  // resumed at 100 ms from message 7's time: message 8 is due 1 ms later
  EXPECT_EQ(out[8].sequence, 8U);
  EXPECT_EQ(out[8].at, kW0 + 101'000'000);
  // quit at 110 ms: messages 8..16 went out (due at 101..109 ms), 17 (110 ms) lost the race to quit
  EXPECT_EQ(out.back().sequence, 16U);
  EXPECT_EQ(stats.published, out.size());
}

TEST_F(PlayerTest, StartPausedAndStepOnly) {
  FakeControl control(kW0);
  PlayerOptions o;
  o.start_paused = true;
  control.at(kW0 + 7, PlayerCommand::kStep);
  control.at(kW0 + 9, PlayerCommand::kStep);
  control.at(kW0 + 11, PlayerCommand::kQuit);
  const auto out = play(o, control);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].at, kW0 + 7);
  EXPECT_EQ(out[1].at, kW0 + 9);
}

TEST_F(PlayerTest, AsFastAsPossibleNeverWaitsForTime) {
  FakeControl control(kW0);
  PlayerOptions o;
  o.as_fast_as_possible = true;
  const auto out = play(o, control);
  ASSERT_EQ(out.size(), 40U);
  for (const Published& p : out) EXPECT_EQ(p.at, kW0);
}

TEST_F(PlayerTest, BadOptions) {
  PlayerOptions o;
  o.rate = 0;
  EXPECT_THROW(Player(*reader_, o), std::invalid_argument);
  o.rate = 1;
  o.filter.topics = {"/zzz"};
  EXPECT_THROW(Player(*reader_, o), McapError);
}

}  // namespace
