#pragma once
/// \file world.hpp
/// \brief The collision world: scene bodies, mannequins (segment capsules posed by the skeleton)
/// and movable objects; one `query` per simulation step returns the contacts of every pair of
/// bodies closer than the activation distance (thesis 3.1.2 d(q), 3.2.1 witness points, Fig. 4.18
/// margins).
///
/// Pipeline of a query:
/// 1. broad phase: FCL dynamic AABB trees (one for static scene bodies, built once; one for the
///    moving colliders, refitted each step) over AABBs inflated by margin + activation/2, so two
///    AABBs overlap whenever the pair may be in range;
/// 2. filters: static–static, same body, adjacent segments and excluded pairs of a mannequin;
/// 3. narrow phase per candidate pair: exact closest points (closed forms for spheres, capsules,
///    planes, boxes; triangles of a mesh reached by walking its FCL BVHModel<OBBRSS> with the
///    inflated shape; FCL's GJK/EPA for the other convex pairs), then a contact manifold of up to
///    4 points for face contacts (box on plane: 4 corners; capsule lying on a face: 2 ends);
/// 4. sort by (body_a, body_b, shape_a, shape_b, feature): the same input gives the same bytes.
///
/// Not thread-safe; one CollisionWorld per thread. query() does not allocate once its buffers have grown.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mannequin/collision/contact.hpp"
#include "mannequin/collision/scene.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::collision {

struct WorldOptions {
  double activation_distance = 0.02;  ///< report pairs with distance (after margins) ≤ this (m)
  int max_points_per_pair = 4;        ///< contact manifold size (1..8)
  double face_angle_deg = 15.0;       ///< a face is a support face if its normal is this close to the contact normal
};

/// How a mannequin's segments collide.
struct MannequinOptions {
  std::string name;          ///< body name prefix; empty: "mannequin<k>"
  double margin = 0.0;       ///< margin of every segment (m)
  bool self_collision = true;
  /// Segments carried by the same joint, or by a joint and the nearest ancestor joint carrying a
  /// segment (parent segment), never collide with each other.
  bool exclude_adjacent = true;
  /// Also exclude the pairs that already touch or overlap (distance ≤ 0, margins ignored) in the
  /// neutral configuration q = 0 (anatomical posture): with the shipped mannequins, forearms and
  /// hands against thighs and pelvis, clavicles with each other and the head... (docs/collision.md).
  bool exclude_touching_at_neutral = true;
  /// Further excluded pairs of segment names (e.g. {"hand_l", "thigh_l"}).
  std::vector<std::pair<std::string, std::string>> exclude_pairs;
  /// Feet as boxes (the capsule's bounding box: flat sole, 4-point support) instead of capsules.
  bool foot_boxes = true;
};

/// Kinds of bodies.
enum class BodyKind { kStatic, kMovable, kSegment };

class CollisionWorld {
 public:
  explicit CollisionWorld(const WorldOptions& options = {});
  ~CollisionWorld();
  CollisionWorld(CollisionWorld&&) noexcept;
  CollisionWorld& operator=(CollisionWorld&&) noexcept;
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  /// Adds every body of a scene as "scene/<name>"; a scene's activation distance, if set, replaces
  /// the CollisionWorld's. Call before the first query. \throws std::invalid_argument on a duplicate name.
  void addScene(const SceneSpec& scene);

  /// Adds one body. \throws std::invalid_argument on a duplicate name, no shape, a negative or
  /// non-finite margin, or a non-finite pose. Returns its body id.
  int addBody(const std::string& name, const std::vector<PlacedShape>& shapes, const SE3& pose,
              BodyKind kind, double margin = 0.0);

  /// Adds a mannequin: one body per segment with a capsule of positive radius, named
  /// "<name>/<segment>", posed by the segment's joint frame. Returns the mannequin index.
  /// \throws std::invalid_argument on an unknown segment in exclude_pairs or a negative margin.
  int addMannequin(const skeleton::Model& model, const MannequinOptions& options = {});

  /// Poses a movable body (world frame). \throws std::invalid_argument for a static or segment
  /// body, an unknown id or a non-finite pose.
  void setBodyPose(int body, const SE3& oMb);
  /// Poses a mannequin's segments from data.oMi (call skeleton::forwardKinematics first).
  /// \throws std::invalid_argument for an unknown mannequin or a data of another size.
  void updateMannequin(int mannequin, const skeleton::Data& data);
  /// Whether a mannequin has a place of its own in the world (default: yes). A mannequin that is not
  /// placed (sim::World: not yet calibrated to its actor, standing where it was built, where others
  /// may stand too) pairs only with the static bodies and its own segments.
  /// \throws std::invalid_argument for an unknown mannequin.
  void setMannequinPlaced(int mannequin, bool placed);
  bool mannequinPlaced(int mannequin) const;
  /// Whether `body` pairs with no segment of `mannequin` (true: such pairs are dropped before the narrow
  /// phase, e.g. an object a hand of that mannequin holds: its shapes sit inside the hand's, where FCL's
  /// GJK/EPA can abort). \throws std::invalid_argument for an unknown body or mannequin (at most 64).
  void setIgnoresMannequin(int body, int mannequin, bool ignore);
  bool ignoresMannequin(int body, int mannequin) const;
  /// Sets a body's margin (m, ≥ 0).
  void setMargin(int body, double margin);

  /// All contacts of the current poses, for simulation step `step`. Clears and refills `out`.
  void query(std::uint64_t step, ContactSet& out);

  int bodyCount() const;
  const std::string& bodyName(int body) const;
  /// Body id by name, −1 if absent.
  int findBody(const std::string& name) const;
  BodyKind bodyKind(int body) const;
  const SE3& bodyPose(int body) const;
  double margin(int body) const;
  /// Body id of a mannequin's segment, −1 when the segment has no collision shape.
  int segmentBody(int mannequin, int segment) const;
  int mannequinCount() const;
  /// Whether two bodies can ever be reported (false for static–static, same body, excluded pairs).
  bool pairEnabled(int body_a, int body_b) const;
  double activationDistance() const;
  void setActivationDistance(double distance);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mannequin::collision
