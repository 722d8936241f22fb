// What a render node draws: scene assets and models, a state's scene, the followed camera, the overlay
// (mannequin/renderservice/drawing.hpp).
#include "mannequin/renderservice/drawing.hpp"

#include <spdlog/spdlog.h>

#include "mannequin/core/clock.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/simservice/config.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::renderservice {

render::SceneAssets loadAssets(const std::string& sim, const std::string& scene) {
  render::SceneAssets a;
  if (!sim.empty()) {
    const simservice::SimServiceConfig cfg = simservice::loadSimConfig(core::findData(sim));
    if (cfg.world.physics.enabled) a.scene = cfg.world.physics.scene;
    for (const auto& m : cfg.mannequins) a.addModel(m.name, skeleton::buildMannequin(skeleton::loadMannequinSpec(m.config)));
  }
  if (!scene.empty()) a.scene = collision::loadScene(core::findData(scene));
  return a;
}

void Models::addMissing(const v1::WorldState& ws) {
  for (const v1::MannequinState& m : ws.mannequins()) {
    if (assets_.capsules.count(m.name()) || assets_.capsules.count(m.model()) || !tried_.insert(m.model()).second) continue;
    try {
      const std::string path = core::findData("configs/mannequins/" + m.model() + ".yaml");
      assets_.addModel(m.model(), skeleton::buildMannequin(skeleton::loadMannequinSpec(path)));
      spdlog::info("mannequin '{}': model '{}' from {}", m.name(), m.model(), path);
    } catch (const std::exception& e) {
      spdlog::warn("mannequin '{}': no model '{}' ({}); drawn as spheres (pass --sim)", m.name(), m.model(), e.what());
    }
  }
}

render::RenderScene sceneOf(const v1::WorldState& ws, const render::SceneAssets& assets, const render::ViewConfig& view,
                            const render::RenderLayers& layers) {
  render::RenderScene s = render::buildScene(ws, assets, view.style);
  render::applyLayers(s, layers);
  return s;
}

render::ViewConfig followedView(const render::ViewConfig& view, const render::OrbitCamera& orbit, const v1::WorldState* ws,
                                const std::string& follow) {
  render::ViewConfig v = view;
  v.orbit = orbit;
  if (ws == nullptr || follow.empty() || view.type != render::ViewConfig::Type::kDesktop) return v;
  v.orbit = render::followed(orbit, *ws, follow, (orbit.target - view.orbit.target).head<2>());
  return v;
}

std::vector<render::OverlayLine> OverlayText::line(const v1::WorldState& ws, bool live) {
  if (!live) return render::overlayLines(ws, nullptr);
  const auto now = std::chrono::steady_clock::now();
  if (last_) {
    const double dt = std::chrono::duration<double>(now - *last_).count();
    if (dt > 0) fps_ = fps_ <= 0 ? 1.0 / dt : 0.9 * fps_ + 0.1 / dt;
  }
  last_ = now;
  const std::int64_t sent = ws.header().send_time_ns();
  const render::OverlayLive stats{fps_, sent > 0 ? static_cast<double>(core::wallNs() - sent) * 1e-6 : 0.0};
  return render::overlayLines(ws, &stats);
}

void OverlayText::draw(render::Renderer& r, const std::vector<render::OverlayLine>& lines,
                       const std::vector<render::EyeView>& eyes, int h) {
  for (const auto& [segments, colour] : render::layoutOverlay(lines, h))
    for (const render::EyeView& e : eyes) r.drawOverlay(segments, e.x, e.width, h, colour);
}

}  // namespace mannequin::renderservice
