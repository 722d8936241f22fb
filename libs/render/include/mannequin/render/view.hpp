#pragma once
/// \file view.hpp
/// \brief View files (configs/views/*.yaml): what one render node shows. Reference in docs/render.md.
///
/// ```yaml
/// name: desktop
/// type: desktop                 # desktop (orbit camera) | wall (off-axis frustum of a VR wall)
/// size: [1280, 720]             # window / default headless size (pixels)
/// background: [0.11, 0.12, 0.14]
/// camera: {target: [0.4, 0, 0.9], distance: 3.6, yaw_deg: 35, pitch_deg: 18, fov_y_deg: 45, near: 0.05, far: 100}
/// ---
/// name: wall_front
/// type: wall
/// size: [1280, 720]
/// wall: {lower_left: [1.5, 1.2, 0.0], lower_right: [1.5, -1.2, 0.0], upper_left: [1.5, 1.2, 1.35]}   # room = world, m
/// head: [0, 0, 1.7]             # the eye; with head_body, until that body is first tracked
/// head_body: head               # optional: the mocap.frame rigid body that carries the eye (live, --connect)
/// head_offset: [0.0, 0.0, 0.08] # optional: the eye in that body's frame (m)
/// near: 0.05
/// far: 100
/// stereo: {eye_separation: 0.065, mode: side_by_side}   # optional: two eyes, left image on the left half
/// ```
/// Optional in both: `style: {force_scale: 0.002, force_full: 400}` (m per N, N at full red);
/// `layers: {mannequins: true, scene: true, objects: true, contacts: true, balance: true, control_frames: true,
/// overlay: false}` (what is drawn). Desktop only: `follow: operator` (a mannequin name, or its index in
/// sim.world): the orbit camera's target tracks that mannequin's pelvis horizontally.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/render/camera.hpp"
#include "mannequin/render/scene.hpp"

namespace mannequin::v1 {
class MocapFrame;
}

namespace mannequin::render {

/// Stereo of a wall view: two off-axis frusta from head ∓ eye_separation/2 · vr (vr = the wall's right axis,
/// lower_left → lower_right). Side by side: each eye fills one half of the image (left eye on the left),
/// the wall squeezed horizontally into it (the "half side-by-side" input of stereo projectors).
struct Stereo {
  enum class Mode { kSideBySide };
  bool enabled = false;
  double eye_separation = 0.065;  ///< m
  Mode mode = Mode::kSideBySide;
};

/// One eye's camera and the columns [x, x + width) of the image it fills (all rows).
struct EyeView {
  Camera camera;
  int x = 0, width = 0;
};

struct ViewConfig {
  enum class Type { kDesktop, kWall };
  std::string name = "view";
  std::string source;          ///< file it was read from
  Type type = Type::kDesktop;
  int width = 1280, height = 720;
  std::array<float, 3> background{0.11f, 0.12f, 0.14f};
  OrbitCamera orbit;           ///< kDesktop
  Wall wall;                   ///< kWall
  Vec3 head{0.0, 0.0, 1.7};    ///< kWall: the eye (room = world, m)
  std::string head_body;       ///< kWall: the mocap.frame rigid body carrying the eye ("" : the head is fixed)
  Vec3 head_offset = Vec3::Zero();  ///< kWall: the eye in head_body's frame (m)
  double near_plane = 0.05, far_plane = 100.0;  ///< kWall (the orbit camera has its own)
  Style style;
  RenderLayers layers;          ///< `layers:` what is drawn
  std::string follow;           ///< kDesktop `follow:` mannequin name or index ("": the target stays put)
  Stereo stereo;                ///< kWall `stereo:`
  bool sync = false;            ///< `sync: true`: live nodes pass the swap barrier (render.sync) before each swap
  double sync_timeout = 0.5;    ///< `sync_timeout`: s a node waits for a peer that is late or dead before going on

  /// The camera of this view for an image of width × height (desktop: the orbit camera at that aspect;
  /// wall: the off-axis frustum from `head`, independent of the image size).
  Camera camera(int image_width, int image_height) const;
  /// What to draw into an image_width × image_height image: the one camera() over the whole image, or with
  /// stereo the left eye's wall camera on columns [0, w/2) and the right eye's on [w/2, w).
  /// \throws std::invalid_argument when an eye is on or behind the wall plane (see wallCamera).
  std::vector<EyeView> eyes(int image_width, int image_height) const;
};

/// \throws core::ConfigError "FILE:LINE: field 'camera.distance': ..." (unknown key, bad value, a wall
/// whose edges are not orthogonal, a head behind the wall).
ViewConfig parseView(const std::string& yaml_text, const std::string& source);
ViewConfig loadView(const std::string& path);

/// The eye position from a mocap frame: head_body's pose · head_offset, when the view has a head_body and
/// the frame has that body tracked with a finite pose; nullopt otherwise (keep the previous head).
std::optional<Vec3> trackedHead(const v1::MocapFrame& frame, const ViewConfig& view);

/// The point a view following `follow` tracks in `state`: the mannequin named `follow` (or, when `follow` is a
/// whole number and no mannequin has that name, the one at that index): its segment "pelvis", else its first
/// segment, else its CoM. nullopt when there is no such mannequin or it has none of these.
std::optional<Vec3> followPoint(const v1::WorldState& state, const std::string& follow);

/// `orbit` with its target moved horizontally onto followPoint(state, follow) plus `offset` (x, y; the user's
/// pan in a window); unchanged when there is no such point (and when `follow` is empty).
OrbitCamera followed(const OrbitCamera& orbit, const v1::WorldState& state, const std::string& follow,
                     const Eigen::Vector2d& offset = Eigen::Vector2d::Zero());

/// "1280x720" → (1280, 720). \throws std::invalid_argument naming the text.
std::array<int, 2> parseSize(const std::string& text);

}  // namespace mannequin::render
