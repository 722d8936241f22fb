#pragma once
/// \file drawing.hpp
/// \brief What a render node draws, whatever its source and output: the scene's geometry (the sim
/// config's scene and mannequin models, or --scene; models met later looked up by name), the scene of
/// one sim.world state with the hidden layers removed, the followed camera of a desktop view, and the
/// text overlay.
#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "mannequin/render/overlay.hpp"
#include "mannequin/render/renderer.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::renderservice {

/// Geometry: the sim config `sim`'s scene and mannequins, or the scene file `scene` (which overrides the
/// sim config's; either may be empty). \throws core::ConfigError naming the file and line.
render::SceneAssets loadAssets(const std::string& sim, const std::string& scene);

/// The models of `assets`, completed on the way: a mannequin of a state whose model is not loaded is
/// looked up once as configs/mannequins/<model>.yaml (else drawn as spheres, with a warning).
class Models {
 public:
  explicit Models(render::SceneAssets assets) : assets_(std::move(assets)) {}
  /// Loads the models of `ws` not tried yet.
  void addMissing(const v1::WorldState& ws);
  const render::SceneAssets& assets() const { return assets_; }

 private:
  render::SceneAssets assets_;
  std::set<std::string> tried_;
};

/// What a frame draws of `ws`: its scene with the hidden layers removed.
render::RenderScene sceneOf(const v1::WorldState& ws, const render::SceneAssets& assets, const render::ViewConfig& view,
                            const render::RenderLayers& layers);

/// `view` with its orbit camera's target on the followed mannequin (desktop views with `follow`, or `follow`
/// given: the window's key F), shifted by the user's pan since the start (`orbit` − the view's own).
render::ViewConfig followedView(const render::ViewConfig& view, const render::OrbitCamera& orbit, const v1::WorldState* ws,
                                const std::string& follow);

/// The overlay's lines (render::overlayLines): the sim.world step and time; live also the render fps (frames
/// drawn per second, smoothed) and the lateness (now − the state's send time, ms); the sim's lag behind mocap,
/// the stale-contact flag and the scenario line. Recordings show no fps nor lateness, so their frames stay
/// deterministic.
class OverlayText {
 public:
  std::vector<render::OverlayLine> line(const v1::WorldState& ws, bool live);
  /// In every eye's part of the image (a stereo wall: the same text in both halves, on the screen plane).
  static void draw(render::Renderer& r, const std::vector<render::OverlayLine>& lines,
                   const std::vector<render::EyeView>& eyes, int h);

 private:
  std::optional<std::chrono::steady_clock::time_point> last_;
  double fps_ = 0;
};

}  // namespace mannequin::renderservice
