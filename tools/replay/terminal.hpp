#pragma once
// ReplayControl of mannequin-replay: the monotonic clock, keys from the terminal (space = pause,
// n or s = step, q = quit; only when stdin is a TTY, put in non-canonical no-echo mode and
// restored on destruction), Ctrl-C, and a hook called at least every 50 ms while waiting.
#include <termios.h>

#include <atomic>
#include <functional>

#include "mannequin/recording/replay.hpp"

namespace mannequin::tools {

class TerminalControl : public recording::ReplayControl {
 public:
  /// interactive: read keys from stdin (ignored when stdin is not a TTY); start_paused: the
  /// player starts paused (for the messages shown on key presses).
  TerminalControl(const std::atomic<bool>& stop, bool interactive, std::function<void()> idle, bool start_paused = false);
  ~TerminalControl() override;
  TerminalControl(const TerminalControl&) = delete;
  TerminalControl& operator=(const TerminalControl&) = delete;

  recording::WallTime now() override;
  recording::PlayerCommand waitUntil(recording::WallTime deadline) override;
  bool interactive() const { return tty_; }

 private:
  const std::atomic<bool>& stop_;
  std::function<void()> idle_;
  bool tty_ = false;
  bool paused_ = false;
  termios saved_{};
};

}  // namespace mannequin::tools
