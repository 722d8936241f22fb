#pragma once
/// \file render_node.hpp
/// \brief One render node, one view (docs/render.md): a frame source (a recording, the static scene, the
/// live sim.world, or the live sim.world through the swap barrier of synchronised nodes) drawn into an
/// output (PNG frames headless, or a window), in the service kit's loop: with --publish (a node of a
/// deployment) it heartbeats like every service (state RUNNING while it draws, frames counted in the loop
/// rate, stat `frames`).
#include <atomic>
#include <memory>
#include <optional>

#include "mannequin/render/renderer.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/renderservice/drawing.hpp"
#include "mannequin/renderservice/frame_source.hpp"
#include "mannequin/renderservice/options.hpp"
#include "mannequin/renderservice/output.hpp"
#include "mannequin/service/runtime.hpp"

namespace mannequin::renderservice {

class RenderNode {
 public:
  /// Binds the node's publisher when `endpoints.publish` is not empty (its heartbeats, render.sync).
  RenderNode(NodeOptions options, render::ViewConfig view, render::SceneAssets assets, service::Endpoints endpoints,
             zmq::context_t& context, double heartbeat_period = 0.5);
  /// Draws until the source ends (headless: a recording or the static scene), --frames, a closed window, a
  /// stop signal or (live) `duration_s`. Exit codes: core::kExitOk; kExitUsage when the output cannot open
  /// or sync lacks --connect/--publish; kExitFailure for a recording without sim.world messages (headless).
  int run(const std::atomic<bool>& stop, double duration_s);

 private:
  void draw(render::Renderer& renderer, FrameSource& source, Output& output, const Frame& frame);
  /// One frame drawn and shown (through the swap barrier for a synced source).
  void show(render::Renderer& renderer, FrameSource& source, Output& output, const Frame& frame, bool synced);

  NodeOptions options_;
  render::ViewConfig view_;
  Models models_;
  service::Endpoints endpoints_;
  zmq::context_t& context_;
  std::unique_ptr<transport::Publisher> publisher_;
  std::unique_ptr<transport::HealthReporter> health_;
  std::optional<render::RenderScene> still_;  // the static scene (no state), built once
  OverlayText overlay_;
  long long frames_ = 0;                       // frames shown
};

}  // namespace mannequin::renderservice
