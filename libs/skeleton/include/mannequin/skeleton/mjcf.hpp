#pragma once
/// \file mjcf.hpp
/// \brief Export of a mannequin Model as MuJoCo's MJCF (XML), for the bench-step comparison with
/// MuJoCo (issue 13) and for anyone who wants to look at a mannequin in MuJoCo's viewer.
///
/// The export, per joint of the tree (parents first), one nested <body> named as the joint, placed
/// at the joint's placement (pos, quat w x y z) in its parent's body:
/// - kFreeFlyer (root): <freejoint>; MuJoCo's qpos is then the body's world pose (p, quaternion),
///   ours placement · [exp(r), p] (see mjcfQpos).
/// - kRevolute: <joint type="hinge"> about the joint's axis, range [lower, upper] when both are finite.
/// - kBall: <joint type="ball">; MuJoCo's ball limit bounds the total rotation angle only, so an
///   enabled swing/twist limit becomes range="0 BallLimit::maxSwing()" (the cone through the swing
///   ellipse's farthest point: looser than ours in swing, and the twist has no separate limit);
///   nq is 4 (a quaternion) where ours is 3, nv is 3 as ours.
/// The first segment carried by a joint gives the body's <inertial> (mass, pos = CoM, fullinertia about
/// the CoM in the joint-frame axes; massless: see MjcfOptions::massless_mass); each further segment on
/// the same joint is a child body without a
/// joint (welded) named as the segment. Each segment with a capsule (radius > 0) gets a geom named as
/// the segment: a capsule from a to b, or, for the feet with foot_boxes, the capsule's bounding box
/// oriented as collision::CollisionWorld::addMannequin orients it (flat sole) — the same shapes as our
/// collision world. Inertia never comes from the geoms (compiler inertiafromgeom="false").
#include <string>
#include <vector>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

struct MjcfOptions {
  double timestep = 0.001;                 ///< s
  Vector3 gravity = Vector3(0, 0, -9.81);  ///< m/s²
  bool floor = true;                       ///< a plane z = 0 (geom "floor")
  bool foot_boxes = true;                  ///< feet (segments named foot*) as boxes, as collision::MannequinOptions
  /// Contacts between the mannequin's own geoms (off: conaffinity 0 on the mannequin, only the floor and
  /// the extra geoms touch it; on: every pair MuJoCo does not exclude as parent/child).
  bool self_collision = false;
  double friction = 0.5;                   ///< sliding friction of the mannequin and the floor geoms
  /// MuJoCo refuses a moving body without mass: a massless segment (or a joint without a segment) gets
  /// this mass (kg) and diagonal inertia (kg·m²) at its CoM, so MuJoCo's total mass exceeds ours by
  /// massless_mass per such body.
  double massless_mass = 1e-6;
  double massless_inertia = 1e-9;
  /// MuJoCo's preallocated contact and constraint buffers (<size nconmax njmax>; 0: MuJoCo's default,
  /// 100 contacts in MuJoCo 2.2).
  int nconmax = 0;
  int njmax = 0;
  /// Raw XML inserted at the end of <worldbody> (static obstacles of a benchmark scene).
  std::string extra_worldbody;
};

/// The MJCF document of `model` (a complete <mujoco model="..."> element).
/// \throws std::invalid_argument when the model cannot be exported (no joint, a non-finite value).
std::string toMjcf(const Model& model, const MjcfOptions& options = {});

/// MuJoCo's qpos for our configuration `q` of `model`, in MuJoCo's order (the bodies' depth-first order
/// in the document, children in joint index order; not always our q's order): the free flyer as (position, quaternion w x y z)
/// of the root body in the world, each ball joint as a quaternion, each revolute angle as is;
/// size nq + 1 (free flyer) + the number of ball joints. \throws std::invalid_argument on a size mismatch.
std::vector<double> mjcfQpos(const Model& model, const VectorX& q);

}  // namespace mannequin::skeleton
