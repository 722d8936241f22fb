#pragma once
/// \file replay.hpp
/// \brief Replay timing without I/O: ReplayClock maps recording time (message log_time, ns)
/// to wall time (a monotonic clock, ns) at a rate factor, with pause, step and rate change;
/// Player walks an McapReader's messages through it, asking a ReplayControl for the time and
/// for the user's commands, and hands each message to a publish callback. Tests inject a fake
/// ReplayControl, so nothing here sleeps on its own.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "mannequin/recording/mcap.hpp"
#include "mannequin/recording/mcap_reader.hpp"

namespace mannequin::recording {

/// Wall-clock nanoseconds from a monotonic clock.
using WallTime = std::int64_t;
/// "Never": the deadline of a paused player.
inline constexpr WallTime kNever = std::numeric_limits<WallTime>::max();

/// Maps recording time to wall time: wall(t) = wall_anchor + (t - rec_anchor) / rate while
/// running. Pausing freezes the recording time; resuming re-anchors so that playback goes on
/// from where it stopped (the pause does not count). Stepping while paused moves the frozen
/// recording time forward.
class ReplayClock {
 public:
  /// rate > 0 (1 = original timing, 2 = twice as fast); throws std::invalid_argument otherwise.
  explicit ReplayClock(double rate = 1.0);

  /// Recording time rec plays at wall time now.
  void start(Timestamp rec, WallTime now);
  /// Wall time at which the message with log_time t is due; kNever while paused.
  WallTime due(Timestamp t) const;
  /// Recording time that corresponds to wall time now (the frozen time while paused).
  Timestamp recordingTime(WallTime now) const;

  void pause(WallTime now);
  void resume(WallTime now);
  bool paused() const { return paused_; }
  /// While paused: recording time jumps to t (the message just stepped to).
  void stepTo(Timestamp t);
  /// Changes the rate without a jump in recording time.
  void setRate(double rate, WallTime now);
  double rate() const { return rate_; }

 private:
  double rate_;
  Timestamp rec_anchor_ = 0;
  WallTime wall_anchor_ = 0;
  bool paused_ = false;
  Timestamp frozen_ = 0;
};

/// What the user asked for while the player waited.
enum class PlayerCommand { kNone, kTogglePause, kStep, kQuit };

/// Time source and user input of a Player (the terminal in mannequin-replay, a script in tests).
class ReplayControl {
 public:
  virtual ~ReplayControl() = default;
  /// Monotonic wall time, ns.
  virtual WallTime now() = 0;
  /// Waits until now() >= deadline (kNever: indefinitely) or until the user gives a command.
  /// Returns kNone when the deadline passed, else the command (at once if one is pending).
  virtual PlayerCommand waitUntil(WallTime deadline) = 0;
};

/// How to replay.
struct PlayerOptions {
  double rate = 1.0;          ///< rate factor of the original timing (> 0)
  bool as_fast_as_possible = false;  ///< ignore timing (lockstep: the publish callback blocks until acknowledged)
  bool loop = false;          ///< start again at the end (until quit, or max_loops)
  std::uint64_t max_loops = 0;  ///< with loop: stop after this many passes (0 = forever)
  bool start_paused = false;  ///< wait for a toggle or step before the first message
  ReadFilter filter;          ///< time range (log_time, ns) and topics
};

/// Outcome of Player::run.
struct PlayerStats {
  std::uint64_t published = 0;  ///< messages handed to publish
  std::uint64_t passes = 0;     ///< complete passes over the filtered messages
  bool quit = false;            ///< stopped by PlayerCommand::kQuit
};

/// Replays an McapReader's messages.
class Player {
 public:
  using Publish = std::function<void(const Message&, const Channel&)>;

  /// Throws std::invalid_argument on a rate <= 0 or NaN, McapError on an unknown topic.
  Player(const McapReader& reader, PlayerOptions options);
  /// Plays until the end (or forever with loop), publishing each message when it is due.
  /// Messages are due at the ReplayClock time of their log_time, the first one of each pass
  /// at once. Throws McapError when a chunk turns out to be corrupt (what was published
  /// before stays published).
  PlayerStats run(ReplayControl& control, const Publish& publish);

 private:
  const McapReader& reader_;
  PlayerOptions options_;
};

}  // namespace mannequin::recording
