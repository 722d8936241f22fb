#include "terminal.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include <spdlog/spdlog.h>

namespace mannequin::tools {

TerminalControl::TerminalControl(const std::atomic<bool>& stop, bool interactive, std::function<void()> idle,
                                 bool start_paused)
    : stop_(stop), idle_(std::move(idle)), paused_(start_paused) {
  if (interactive && ::isatty(STDIN_FILENO) == 1 && ::tcgetattr(STDIN_FILENO, &saved_) == 0) {
    termios raw = saved_;
    raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    tty_ = ::tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
}

TerminalControl::~TerminalControl() {
  if (tty_) ::tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
}

recording::WallTime TerminalControl::now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

recording::PlayerCommand TerminalControl::waitUntil(recording::WallTime deadline) {
  constexpr recording::WallTime kSlice = 50'000'000;  // 50 ms: Ctrl-C and subscriptions stay responsive
  while (true) {
    if (stop_.load()) return recording::PlayerCommand::kQuit;
    if (idle_) idle_();
    const recording::WallTime t = now();
    if (t >= deadline) return recording::PlayerCommand::kNone;
    const recording::WallTime wait = std::min(deadline - t, kSlice);
    if (tty_) {
      pollfd p{STDIN_FILENO, POLLIN, 0};
      const int timeout_ms = static_cast<int>((wait + 999'999) / 1'000'000);
      if (::poll(&p, 1, wait < 1'000'000 ? 0 : timeout_ms) > 0 && (p.revents & POLLIN)) {
        char c = 0;
        if (::read(STDIN_FILENO, &c, 1) == 1) {
          switch (c) {
            case ' ':
              paused_ = !paused_;
              spdlog::info(paused_ ? "paused (space = resume, n = step)" : "resumed");
              return recording::PlayerCommand::kTogglePause;
            case 'n':
            case 's':
              if (!paused_) spdlog::info("paused; stepping (space = resume)");
              paused_ = true;
              return recording::PlayerCommand::kStep;
            case 'q': return recording::PlayerCommand::kQuit;
            default: break;
          }
        }
        continue;
      }
      if (wait < 1'000'000) std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
    } else {
      std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
    }
  }
}

}  // namespace mannequin::tools
