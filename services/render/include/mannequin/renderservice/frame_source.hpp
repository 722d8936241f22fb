#pragma once
/// \file frame_source.hpp
/// \brief Where a render node's frames come from: a recording (every message, or at its own pace in a
/// window), the static scene, the live sim.world of publishers, or the live sim.world in lockstep with the
/// other nodes of a synchronised view (the swap barrier).
#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/render/view.hpp"
#include "mannequin/renderservice/swap_barrier.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::renderservice {

/// One frame to draw.
struct Frame {
  const v1::WorldState* state = nullptr;  ///< the state drawn; nullptr: the static scene
  std::uint64_t index = 0;                ///< names the PNG: message index, arrival count or sim.world step
  bool live = false;                      ///< the overlay shows the render fps and the lateness
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt when there is none this turn (a live source waited up to its poll period).
  virtual std::optional<Frame> next() = 0;
  /// No frame will come any more (a recording played to its end, the static scene given).
  virtual bool finished() const { return false; }
  /// The camera(s) of `view` for a w×h image (a live source: with the tracked head).
  virtual std::vector<render::EyeView> eyes(const render::ViewConfig& view, int w, int h) { return view.eyes(w, h); }
  /// The frame is drawn and about to be shown (the swap barrier waits for the peers here).
  virtual void drawn(const Frame&) {}
  /// The frame is shown (swapped, or written).
  virtual void shown(const Frame&) {}
  /// The run ends.
  virtual void finish() {}
};

/// Every sim.world message of a recording, in log-time order. \throws std::runtime_error (no sim.world
/// channel: listing the file's topics; a message that is not a WorldState).
std::vector<v1::WorldState> readRecording(const std::string& path);

/// A recording's states: every `every`th message, named by its index (headless), or in a window the state
/// of the recording's sim time at the wall time since the start, looping.
class RecordingSource final : public FrameSource {
 public:
  enum class Pace { kEveryMessage, kWallClock };
  RecordingSource(std::vector<v1::WorldState> states, Pace pace, int every = 1);
  std::optional<Frame> next() override;
  bool finished() const override;

 private:
  std::vector<v1::WorldState> states_;
  Pace pace_;
  std::size_t every_, next_ = 0;
  std::chrono::steady_clock::time_point start_;
};

/// The static scene (no state), once.
class StaticSource final : public FrameSource {
 public:
  std::optional<Frame> next() override;
  bool finished() const override { return given_; }

 private:
  bool given_ = false;
};

/// The newest sim.world of the publishers connected to (kLatest: a backlog is skipped; the publisher re-sends
/// its last state to a late subscriber, so a node shows the current scene at once); with `view.sync` every
/// state is kept, the last 512 by step (the swap barrier shows the leader's step). A wall view with
/// `head_body` takes its eye from that rigid body of mocap.frame (same endpoints).
class LiveWorld {
 public:
  LiveWorld(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view);
  /// The camera(s) of `view` with the tracked head when there is one; a head that left the room (an eye
  /// behind the wall) keeps the last usable cameras.
  const std::vector<render::EyeView>& eyes(const render::ViewConfig& view, int w, int h);
  /// Waits up to `timeout` for traffic; true when a newer state than the last call's arrived.
  bool poll(std::chrono::microseconds timeout);
  const v1::WorldState& latest() const { return latest_; }
  long long received() const { return received_; }
  transport::Subscriber& subscriber() { return sub_; }
  /// Sync mode: the newest step received (0: none yet).
  std::uint64_t newestStep() const { return ring_.empty() ? 0 : ring_.rbegin()->first; }
  /// Sync mode: the state of step `step`, or (missed: dropped upstream or out of the ring) the newest one
  /// before it, else the oldest kept; nullptr when nothing arrived.
  const v1::WorldState* stateAt(std::uint64_t step) const;

 private:
  static constexpr std::size_t kRing = 512;
  std::map<std::uint64_t, v1::WorldState> ring_;
  transport::Subscriber sub_;
  v1::WorldState latest_;
  long long received_ = 0, seen_ = 0;
  std::optional<render::Vec3> head_;
  std::vector<render::EyeView> eyes_;
};

/// Live: a frame per new state (every `every`th, named by its arrival count), waiting up to `poll` for one.
class LiveSource final : public FrameSource {
 public:
  LiveSource(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view,
             std::chrono::microseconds poll, int every);
  std::optional<Frame> next() override;
  std::vector<render::EyeView> eyes(const render::ViewConfig& view, int w, int h) override { return live_.eyes(view, w, h); }

 private:
  LiveWorld live_;
  std::chrono::microseconds poll_;
  long long every_, states_ = 0;
};

/// Synchronised nodes (view `sync: true`): the step the swap barrier picks (the leader's newest state, or
/// as a follower the leader's post), named by that step; drawn() waits in the barrier until every live
/// peer drew it; shown() logs the swap in `swaps_log` ("step steady_ns"; empty path: no log). The
/// barrier posts on `publisher` as `name`; `pump` runs in its waits (a window's events), `over` ends them.
class SyncedSource final : public FrameSource {
 public:
  SyncedSource(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view,
               transport::Publisher& publisher, const std::string& name, std::function<bool()> over,
               std::function<void()> pump, const std::string& swaps_log);
  std::optional<Frame> next() override;
  std::vector<render::EyeView> eyes(const render::ViewConfig& view, int w, int h) override { return live_.eyes(view, w, h); }
  void drawn(const Frame& frame) override;
  void shown(const Frame& frame) override;
  void finish() override;

 private:
  std::optional<std::uint64_t> pick();
  LiveWorld live_;
  double timeout_s_;
  std::function<bool()> over_;
  SwapBarrier barrier_;
  std::ofstream log_;
  bool greeted_ = false;
  std::uint64_t last_ = 0;
};

}  // namespace mannequin::renderservice
