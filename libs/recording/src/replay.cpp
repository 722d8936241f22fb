#include "mannequin/recording/replay.hpp"

#include <cmath>
#include <stdexcept>

namespace mannequin::recording {

namespace {

void checkRate(double rate) {
  if (!(rate > 0.0) || !std::isfinite(rate)) {
    throw std::invalid_argument("replay rate must be a finite number > 0, got " + std::to_string(rate));
  }
}

}  // namespace

ReplayClock::ReplayClock(double rate) : rate_(rate) { checkRate(rate); }

void ReplayClock::start(Timestamp rec, WallTime now) {
  rec_anchor_ = rec;
  wall_anchor_ = now;
  frozen_ = rec;
}

WallTime ReplayClock::due(Timestamp t) const {
  if (paused_) return kNever;
  if (t <= rec_anchor_) {
    // earlier than the anchor (out of order or stepped past): due now-ish, never before the anchor
    const double back = static_cast<double>(rec_anchor_ - t) / rate_;
    return wall_anchor_ - static_cast<WallTime>(std::llround(back));
  }
  const Timestamp dt = t - rec_anchor_;
  if (rate_ == 1.0) return wall_anchor_ + static_cast<WallTime>(dt);  // exact integer path
  return wall_anchor_ + static_cast<WallTime>(std::llround(static_cast<double>(dt) / rate_));
}

Timestamp ReplayClock::recordingTime(WallTime now) const {
  if (paused_) return frozen_;
  if (now <= wall_anchor_) return rec_anchor_;
  const WallTime dw = now - wall_anchor_;
  if (rate_ == 1.0) return rec_anchor_ + static_cast<Timestamp>(dw);
  return rec_anchor_ + static_cast<Timestamp>(std::llround(static_cast<double>(dw) * rate_));
}

void ReplayClock::pause(WallTime now) {
  if (paused_) return;
  frozen_ = recordingTime(now);
  paused_ = true;
}

void ReplayClock::resume(WallTime now) {
  if (!paused_) return;
  paused_ = false;
  rec_anchor_ = frozen_;
  wall_anchor_ = now;
}

void ReplayClock::stepTo(Timestamp t) {
  if (paused_ && t > frozen_) frozen_ = t;
}

void ReplayClock::setRate(double rate, WallTime now) {
  checkRate(rate);
  if (!paused_) {
    rec_anchor_ = recordingTime(now);
    wall_anchor_ = now;
  }
  rate_ = rate;
}

Player::Player(const McapReader& reader, PlayerOptions options) : reader_(reader), options_(std::move(options)) {
  checkRate(options_.rate);
  if (!options_.filter.topics.empty()) (void)reader_.channelsOf(options_.filter.topics);
}

PlayerStats Player::run(ReplayControl& control, const Publish& publish) {
  PlayerStats stats;
  ReplayClock clock(options_.rate);
  bool paused = options_.start_paused;
  while (true) {
    MessageCursor cursor = reader_.messages(options_.filter);
    Message m;
    if (!cursor.next(m)) return stats;  // nothing to play (also ends a loop over nothing)
    clock.start(m.log_time, control.now());
    if (paused) clock.pause(control.now());
    bool have = true;
    while (have) {
      const WallTime deadline = paused ? kNever : options_.as_fast_as_possible ? control.now() : clock.due(m.log_time);
      const PlayerCommand cmd = control.waitUntil(deadline);
      switch (cmd) {
        case PlayerCommand::kQuit:
          stats.quit = true;
          return stats;
        case PlayerCommand::kTogglePause:
          paused = !paused;
          if (paused) {
            clock.pause(control.now());
          } else {
            clock.resume(control.now());
          }
          continue;
        case PlayerCommand::kStep:
          if (!paused) {  // a step while running pauses first, then steps
            paused = true;
            clock.pause(control.now());
          }
          clock.stepTo(m.log_time);
          break;
        case PlayerCommand::kNone:
          if (!paused && !options_.as_fast_as_possible && control.now() < deadline) continue;  // woke early
          if (paused) continue;
          break;
      }
      publish(m, reader_.channel(m.channel_id));
      ++stats.published;
      have = cursor.next(m);
    }
    ++stats.passes;
    if (!options_.loop || (options_.max_loops != 0 && stats.passes >= options_.max_loops)) return stats;
  }
}

}  // namespace mannequin::recording
