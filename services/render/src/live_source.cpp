// Frames of the live sim.world: the newest state of the publishers, or the step the swap barrier of
// synchronised nodes picks (mannequin/renderservice/frame_source.hpp).
#include <filesystem>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "mannequin/renderservice/frame_source.hpp"
#include "mannequin/transport/topics.hpp"

namespace mannequin::renderservice {

LiveWorld::LiveWorld(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view)
    : sub_(context, std::move(options)) {
  if (view.sync) {
    // the swap barrier shows the leader's step: every state is kept (queue delivery), the last kRing by step
    static constexpr transport::Topic<v1::WorldState> kWorldQueued{transport::topics::kSimWorld.name,
                                                                    transport::Delivery::kQueue};
    sub_.subscribe(kWorldQueued, [this](const v1::WorldState& ws) {
      latest_ = ws;
      ++received_;
      ring_[ws.step()] = ws;
      if (ring_.size() > kRing) ring_.erase(ring_.begin());
    });
  } else {
    sub_.subscribe(transport::topics::kSimWorld, [this](const v1::WorldState& ws) {
      latest_ = ws;
      ++received_;
    });
  }
  if (!view.head_body.empty())  // a wall with a tracked head: its eye follows that rigid body of mocap.frame
    sub_.subscribe(transport::topics::kMocapFrame, [this, &view](const v1::MocapFrame& f) {
      if (const auto h = render::trackedHead(f, view)) head_ = h;
    });
}

const std::vector<render::EyeView>& LiveWorld::eyes(const render::ViewConfig& view, int w, int h) {
  render::ViewConfig v = view;
  if (head_) v.head = *head_;
  try {
    eyes_ = v.eyes(w, h);
  } catch (const std::invalid_argument&) {
    if (eyes_.empty() || eyes_.back().x + eyes_.back().width != w) eyes_ = view.eyes(w, h);
  }
  return eyes_;
}

bool LiveWorld::poll(std::chrono::microseconds timeout) {
  sub_.poll(timeout);
  const bool fresh = received_ != seen_;
  seen_ = received_;
  return fresh;
}

const v1::WorldState* LiveWorld::stateAt(std::uint64_t step) const {
  if (ring_.empty()) return nullptr;
  auto it = ring_.upper_bound(step);
  if (it == ring_.begin()) return &it->second;
  return &std::prev(it)->second;
}

LiveSource::LiveSource(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view,
                       std::chrono::microseconds poll, int every)
    : live_(context, std::move(options), view), poll_(poll), every_(every) {}

std::optional<Frame> LiveSource::next() {
  if (!live_.poll(poll_)) return std::nullopt;
  const long long index = states_++;
  if (index % every_ != 0) return std::nullopt;
  return Frame{&live_.latest(), static_cast<std::uint64_t>(index), true};
}

SyncedSource::SyncedSource(zmq::context_t& context, transport::SubscriberOptions options, const render::ViewConfig& view,
                           transport::Publisher& publisher, const std::string& name, std::function<bool()> over,
                           std::function<void()> pump, const std::string& swaps_log)
    : live_(context, std::move(options), view),
      timeout_s_(view.sync_timeout),
      over_(std::move(over)),
      barrier_(
          publisher, name, view.sync_timeout,
          [this, pump = std::move(pump)](std::chrono::microseconds t) {
            live_.poll(t);
            if (pump) pump();
          },
          over_) {
  live_.subscriber().subscribe(transport::topics::kRenderSync, [this](const v1::RenderSync& m) { barrier_.onMessage(m); });
  if (!swaps_log.empty()) {
    const std::filesystem::path dir = std::filesystem::path(swaps_log).parent_path();
    if (!dir.empty()) std::filesystem::create_directories(dir);
    log_.open(swaps_log);
  }
}

// The step to draw next (the leader's newest state, or as a follower the leader's post), or nullopt when
// there is none yet this turn (waited a little; call again). A missed step gives the newest before it.
std::optional<std::uint64_t> SyncedSource::pick() {
  std::uint64_t step = 0;
  if (barrier_.isLeader()) {
    live_.poll(std::chrono::milliseconds(5));
    if (live_.newestStep() <= last_) {
      barrier_.keepAlive(last_);
      return std::nullopt;
    }
    step = live_.newestStep();
  } else {
    const auto f = barrier_.awaitLeader(last_, [&] { return live_.newestStep() > last_; });
    if (!f) return std::nullopt;
    step = *f;
    // the leader's state normally arrived already (same publisher); wait for it up to the timeout
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s_);
    while (live_.newestStep() < step && std::chrono::steady_clock::now() < until && !over_())
      live_.poll(std::chrono::milliseconds(2));
  }
  const v1::WorldState* ws = live_.stateAt(step);
  if (ws == nullptr) return std::nullopt;
  if (ws->step() != step) spdlog::warn("swap barrier: step {} missed here; drawing step {}", step, ws->step());
  return step;
}

std::optional<Frame> SyncedSource::next() {
  if (!greeted_) {  // nodes started together know each other before their first frame
    barrier_.greet();
    greeted_ = true;
  }
  const auto step = pick();
  if (!step) return std::nullopt;
  return Frame{live_.stateAt(*step), *step, true};
}

void SyncedSource::drawn(const Frame& frame) { barrier_.arriveAndWait(frame.index); }

void SyncedSource::shown(const Frame& frame) {
  if (log_.is_open())
    log_ << frame.index << ' ' << std::chrono::steady_clock::now().time_since_epoch().count() << '\n' << std::flush;
  last_ = frame.index;
}

void SyncedSource::finish() {
  spdlog::info("swap barrier: {} peers at the end, {} drops", barrier_.peers(), barrier_.dropped());
}

}  // namespace mannequin::renderservice
