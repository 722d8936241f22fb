#pragma once
/// \file scene.hpp
/// \brief The render scene: what a render node draws, as plain data built from a WorldState
/// (proto/mannequin/v1/world.proto) and the static scene. No OpenGL here, so it is unit-tested alone.
///
/// Frames and units: everything is in the WORLD frame of the simulation (z up, metres, N).
/// Shape frames are collision::Shape's (capsule and cylinder along their local z, centred; box centred
/// with full sizes; plane = the surface {x : n·x = offset}).
///
/// Where the geometry comes from (first slice): the static primitives and objects' shapes from the sim's
/// scene file (collision::loadScene), the segment capsules from the mannequin model (skeleton::Model,
/// built from configs/mannequins/*.yaml) — so a render node today needs the sim's config files. A latched
/// scene-description topic (meshes, primitives, materials) that makes a node independent of them is a
/// later step (issue 14). A mannequin whose model is unknown is drawn as a sphere per segment origin.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mannequin/collision/scene.hpp"
#include "mannequin/math/se3.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::v1 {
class WorldState;
}

namespace mannequin::render {

using math::SE3;
using math::Vector3;

/// Linear RGBA in [0, 1].
using Colour = std::array<float, 4>;

enum class Kind { kSphere, kCapsule, kCylinder, kBox, kPlane, kCone, kMesh };

/// What a primitive belongs to (layers, and what pixel tests look for).
enum class Layer { kScene, kObject, kMannequin, kContact, kForce, kBalance, kControl };

/// One shaded solid, world frame.
struct Primitive {
  Kind kind = Kind::kSphere;
  Layer layer = Layer::kScene;
  SE3 pose;                       ///< shape frame in the world
  double radius = 0.0;            ///< sphere, capsule, cylinder, cone (base) (m)
  double length = 0.0;            ///< capsule (axis segment), cylinder, cone (height, along +z from the base) (m)
  Vector3 size = Vector3::Zero(); ///< box full sizes (m)
  Vector3 normal = Vector3::UnitZ();  ///< plane normal (world); the plane is drawn as a square of side `length`
  double offset = 0.0;            ///< plane offset (m)
  std::shared_ptr<const collision::TriangleMesh> mesh;  ///< kMesh, in the shape frame
  Colour colour{1, 1, 1, 1};
  std::string tag;                ///< "scene:table", "mannequin:alice/thigh_l", "force:alice/hand_l:table", ...
};

/// A polyline (support polygon, ...), world frame, drawn unlit.
struct Polyline {
  std::vector<Vector3> points;
  bool closed = false;
  Colour colour{1, 1, 1, 1};
  Layer layer = Layer::kBalance;
};

/// How the scene is coloured and scaled.
struct Style {
  /// One colour per mannequin, by its index in the WorldState (cycled). Blue-green-violet hues, far from
  /// the force colours (yellow to red) and the greys of the scene.
  std::vector<Colour> mannequin_colours{{0.20f, 0.45f, 0.95f, 1.0f},
                                        {0.20f, 0.80f, 0.40f, 1.0f},
                                        {0.60f, 0.35f, 0.90f, 1.0f},
                                        {0.15f, 0.75f, 0.80f, 1.0f}};
  Colour scene_colour{0.62f, 0.62f, 0.60f, 1.0f};
  Colour floor_colour{0.42f, 0.43f, 0.45f, 1.0f};
  Colour object_colour{0.78f, 0.72f, 0.62f, 1.0f};
  Colour contact_colour{0.05f, 0.05f, 0.05f, 1.0f};
  Colour com_colour{0.95f, 0.95f, 0.95f, 1.0f};
  Colour support_colour{0.90f, 0.90f, 0.45f, 1.0f};
  /// Force arrows: colour from yellow (|F| = 0) to red (|F| ≥ force_full), length force_scale · |F|
  /// clamped to [force_min_length, force_max_length].
  double force_scale = 0.002;       ///< m per N
  double force_full = 400.0;        ///< N at full red
  double force_min_length = 0.05;   ///< m
  double force_max_length = 0.6;    ///< m
  double force_threshold = 1e-3;    ///< N: smaller forces draw no arrow
  double arrow_radius = 0.012;      ///< m (shaft; the cone head is 2.2× as wide and min(40 % of the arrow, 5 radii) long)
  double contact_radius = 0.015;    ///< m
  double com_radius = 0.035;        ///< m
  double support_height = 0.1;      ///< m: pressing contacts with a vertical normal below this span the support polygon
  double plane_extent = 40.0;       ///< m: side of the square a plane is drawn as
  double fallback_segment_radius = 0.05;  ///< m: a segment of a mannequin whose model is unknown
  /// Control frames (MannequinState.control_frames): the achieved pose as small shaded axes (x, y, z as
  /// red, green, blue cylinders), the target as unlit axes lines in lighter tints (grey when the frame is not
  /// tracked), and the error line between their origins in `control_error_colour` (magenta, a hue no other
  /// layer uses) when they are more than control_error_min apart.
  double control_axis_length = 0.08;   ///< m
  double control_axis_radius = 0.004;  ///< m (the achieved pose's axes)
  std::array<Colour, 3> control_axis_colours{{{0.90f, 0.20f, 0.20f, 1.0f}, {0.20f, 0.80f, 0.25f, 1.0f},
                                              {0.25f, 0.35f, 0.95f, 1.0f}}};
  std::array<Colour, 3> control_target_colours{{{1.0f, 0.60f, 0.60f, 1.0f}, {0.60f, 1.0f, 0.60f, 1.0f},
                                                {0.60f, 0.70f, 1.0f, 1.0f}}};
  Colour control_untracked_colour{0.55f, 0.55f, 0.55f, 1.0f};
  Colour control_error_colour{1.0f, 0.20f, 0.85f, 1.0f};
  double control_error_min = 1e-3;     ///< m: closer target and pose draw no error line
};

/// The geometry a node needs besides the WorldState: the static scene and the mannequin models.
struct SceneAssets {
  collision::SceneSpec scene;  ///< bodies; movable ones are drawn at their ObjectState pose when present
  /// Segment capsules (joint frame) of each mannequin, by mannequin name (WorldState mannequins[i].name),
  /// falling back to the model name (mannequins[i].model).
  std::map<std::string, std::map<std::string, skeleton::Capsule>> capsules;

  /// Registers a model's capsules under `key` (a mannequin name or a model name).
  void addModel(const std::string& key, const skeleton::Model& model);
};

/// Everything one frame draws.
struct RenderScene {
  std::vector<Primitive> solids;
  std::vector<Polyline> lines;
  std::uint64_t step = 0;   ///< WorldState.step
  double sim_time = 0.0;    ///< s
  bool contacts_stale = false;

  /// Number of solids on a layer / whose tag starts with `prefix`.
  std::size_t count(Layer layer) const;
  std::size_t countTagged(const std::string& prefix) const;
};

/// Which layers a view draws (view file `layers:`, window keys 1..7; docs/render.md). The overlay is the
/// text line (Renderer::drawOverlay), drawn by the node, not part of the RenderScene.
struct RenderLayers {
  bool mannequins = true;      ///< kMannequin: segment capsules
  bool scene = true;           ///< kScene: static bodies (floor, table, ...)
  bool objects = true;         ///< kObject: movable bodies
  bool contacts = true;        ///< kContact and kForce: contact points and force arrows
  bool balance = true;         ///< kBalance: CoM and support polygon
  bool control_frames = true;  ///< kControl: control frames, targets and error lines
  bool overlay = false;        ///< the text overlay (also on with --overlay)

  static constexpr int kCount = 7;
  /// The view-file keys, in key order (key 1 toggles names()[0], ...).
  static const std::array<const char*, kCount>& names();
  /// The flag of names()[i], i in [0, kCount).
  bool& flag(int i);
  bool flag(int i) const { return const_cast<RenderLayers*>(this)->flag(i); }
  bool shows(Layer layer) const;
};

/// Removes the solids and lines of the layers `layers` hides.
void applyLayers(RenderScene& scene, const RenderLayers& layers);

/// Colour of a force arrow of norm `newtons` (yellow → red over [0, style.force_full]).
Colour forceColour(double newtons, const Style& style);

/// Appends an arrow (cylinder shaft + cone head) from `from` along `vector` (full length |vector|).
void appendArrow(const Vector3& from, const Vector3& vector, double radius, const Colour& colour, Layer layer,
                 const std::string& tag, std::vector<Primitive>& out);

/// The static scene alone (the bodies of assets.scene at their spec poses).
RenderScene buildStaticScene(const SceneAssets& assets, const Style& style = {});

/// The scene of one WorldState:
/// - static bodies of assets.scene (movable ones at the pose of the ObjectState of the same name if any);
/// - per mannequin: a capsule per segment (pose = segments[i].pose · capsule), one colour per mannequin;
/// - per contact: a small sphere at `point` (or the witness midpoint when `point` is unset), and when
///   |force| > threshold an arrow from it along the force ON THE MANNEQUIN (ContactPoint.force is the force on
///   body_a; it is negated when the mannequin's segment "<name>/<segment>" is body_b), length and colour from the norm;
/// - per mannequin: the CoM (sphere) and the support polygon = the convex hull, projected on z = 0, of its
///   pressing contacts (|force| > threshold or normal_force > 0) with a vertical normal (|n_z| > 0.7) lower
///   than style.support_height (the feet on the floor); drawn as a line 4 mm above z = 0;
/// - per control frame (layer kControl): `actual` as small shaded axes, `target` as unlit axes lines and,
///   when they are more than style.control_error_min apart, a line between their origins (see Style).
RenderScene buildScene(const v1::WorldState& state, const SceneAssets& assets, const Style& style = {});

/// Convex hull (counter-clockwise, no collinear points) of points in the plane, by Andrew's monotone chain.
std::vector<std::array<double, 2>> convexHull(std::vector<std::array<double, 2>> points);

}  // namespace mannequin::render
