// The render node: its source and output chosen from the options and the view, composed in the service
// kit's loop (mannequin/renderservice/render_node.hpp).
#include "mannequin/renderservice/render_node.hpp"

#include <filesystem>

#include <spdlog/spdlog.h>

#include "mannequin/core/main.hpp"

namespace mannequin::renderservice {

RenderNode::RenderNode(NodeOptions options, render::ViewConfig view, render::SceneAssets assets, service::Endpoints endpoints,
                       zmq::context_t& context, double heartbeat_period)
    : options_(std::move(options)),
      view_(std::move(view)),
      models_(std::move(assets)),
      endpoints_(std::move(endpoints)),
      context_(context) {
  if (endpoints_.publish.empty()) return;
  publisher_ = std::make_unique<transport::Publisher>(context_, service::publisherOptions(endpoints_));
  health_ = std::make_unique<transport::HealthReporter>(*publisher_, endpoints_.name, nullptr, heartbeat_period);
}

void RenderNode::draw(render::Renderer& renderer, FrameSource& source, Output& output, const Frame& frame) {
  const auto [w, h] = output.size();
  const ViewState& s = output.state();
  if (frame.state != nullptr) models_.addMissing(*frame.state);
  const std::vector<render::EyeView> eyes = source.eyes(followedView(view_, s.orbit, frame.state, s.follow), w, h);
  if (frame.state == nullptr) {
    if (!still_) still_ = render::buildStaticScene(models_.assets(), view_.style);
    render::RenderScene still = *still_;
    render::applyLayers(still, s.layers);
    renderer.draw(still, eyes, h, view_.background);
    return;
  }
  renderer.draw(sceneOf(*frame.state, models_.assets(), view_, s.layers), eyes, h, view_.background);
  if (s.layers.overlay) OverlayText::draw(renderer, overlay_.line(*frame.state, frame.live), eyes, h);
}

void RenderNode::show(render::Renderer& renderer, FrameSource& source, Output& output, const Frame& frame, bool synced) {
  draw(renderer, source, output, frame);
  if (synced) {
    output.finish();       // the pixels read, or the GPU done, before the barrier
    source.drawn(frame);   // every live peer drew this step
  }
  output.present(frame);  // the swap: the frame goes out now
  source.shown(frame);
  ++frames_;
  if (health_) {
    health_->loopIteration();
    health_->setStat("frames", static_cast<double>(frames_));
  }
}

int RenderNode::run(const std::atomic<bool>& stop, double duration_s) {
  const bool headless = options_.headless, live = !endpoints_.connect.empty();
  const bool synced = live && view_.sync;
  std::unique_ptr<Output> output;
  if (headless)
    output = std::make_unique<PngOutput>(options_, view_, synced);
  else
    output = std::make_unique<WindowOutput>(options_, view_);
  if (const int rc = output->open(); rc != core::kExitOk) return rc;
  if (view_.sync && (headless ? live && !publisher_ : !live || !publisher_)) {
    if (headless)
      spdlog::error("{}: sync: true needs --publish ENDPOINT (the node's render.sync; mannequin-launch passes it)", view_.source);
    else
      spdlog::error("{}: sync: true needs --connect (live) and --publish ENDPOINT (the node's render.sync)", view_.source);
    return core::kExitUsage;
  }
  render::Renderer renderer;
  // live sources stop at --duration; a recording or the static scene is rendered whole
  service::ServiceLoop loop(health_.get(), stop, live ? duration_s : 0.0);
  const auto over = [&] {
    return loop.stopping() || (options_.frames > 0 && frames_ >= options_.frames) || output->closed();
  };
  std::unique_ptr<FrameSource> source;
  if (synced) {
    // frames named by the step; each swap logged in DIR/swaps.log ("step steady_ns"), so nodes can be compared
    const std::string log = options_.out.empty() ? std::string() : (std::filesystem::path(options_.out) / "swaps.log").string();
    source = std::make_unique<SyncedSource>(context_, service::subscriberOptions(endpoints_), view_, *publisher_,
                                            endpoints_.name, over, [&] { output->pollEvents(); }, log);
  } else if (live) {
    // headless: a frame per new state (every Nth); a window: the newest state at each of its frames
    source = std::make_unique<LiveSource>(context_, service::subscriberOptions(endpoints_), view_,
                                          headless ? std::chrono::milliseconds(100) : std::chrono::milliseconds(0),
                                          headless ? options_.every : 1);
  } else if (!options_.from.empty()) {
    std::vector<v1::WorldState> states = readRecording(options_.from);
    if (headless && states.empty()) {
      spdlog::error("{}: no sim.world messages", options_.from);
      return core::kExitFailure;
    }
    using Pace = RecordingSource::Pace;
    source = std::make_unique<RecordingSource>(std::move(states), headless ? Pace::kEveryMessage : Pace::kWallClock,
                                               options_.every);
  } else {
    source = std::make_unique<StaticSource>();  // neither a recording nor publishers: the static scene
  }
  Frame current;                        // a window: the frame on the screen until a newer one (first: the scene)
  std::optional<v1::WorldState> held;   // P: the state frozen on the screen
  const auto capped = [&] { return options_.frames > 0 && frames_ >= options_.frames; };
  if (health_) health_->setStat("frames", 0.0);
  loop.run(
      [&] {
        output->pollEvents();
        if (output->closed()) return false;
        if (publisher_) publisher_->poll();
        std::optional<Frame> next = source->next();
        if (synced || headless) {
          if (!next) return !source->finished();
          show(renderer, *source, *output, *next, synced);
          return !capped();
        }
        if (next) current = *next;
        Frame frame = current;
        if (output->state().paused && frame.state != nullptr) {  // not in synchronised nodes
          if (!held) held = *frame.state;
          frame.state = &*held;
        } else if (!output->state().paused) {
          held.reset();
        }
        show(renderer, *source, *output, frame, false);
        return !capped();
      },
      {}, [&] { source->finish(); });
  output->close(frames_);
  return core::kExitOk;
}

}  // namespace mannequin::renderservice
