#pragma once
/// \file contacts.hpp
/// \brief Contact rows from the collision library's witness points (thesis 3.2.1, 3.9–3.15, Alg. 4).
///
/// For a contact (a, b) of a collision query: witness points P_a, P_b in their bodies' frames and the
/// world normal n from a to b (collision/contact.hpp). At q_k (possibly a few steps after the query):
///   p_a = oMa(q_k) P_a,  p_b = oMb(q_k) P_b,  d = n·(p_b − p_a)      (distance after margins, 3.9)
///   J = nᵀ (J_{p_b} − J_{p_a})   split on the systems of a and b     (3.10–3.15)
/// d ≥ 0 is kept to first order at q_{k+1} by the LCP (predictive scheme 3.7): the margin shells may
/// touch, the real geometry stays `margin_a + margin_b` apart (Fig. 4.18). A contact already deeper
/// than the margins comes back at `recovery_speed`, never with a jump.
/// Friction (optional): μ from the material pair of the two bodies, m edges of the linearised cone in
/// the tangent plane (t1, t2 built from n), on the same points.
#include <string>
#include <vector>

#include "mannequin/collision/contact.hpp"
#include "mannequin/constraints/bodies.hpp"
#include "mannequin/constraints/solver.hpp"

namespace mannequin::constraints {

/// Which system and body of it a collision body is.
struct BodyBinding {
  int system = -1;                 ///< −1: static (scene); else index in the ConstraintSolver's systems
  const BodyFrames* frames = nullptr;  ///< null for static bodies
  int local = 0;                   ///< joint index (mannequin) or 0 (object)
  math::SE3 static_pose;           ///< pose of a static body
  int material = 0;                ///< index in the friction table
  double margin = 0.0;             ///< the body's margin (m): penetration of the real geometry = −(d + margins)
};

struct ContactOptions {
  int friction_edges = 4;        ///< m; 0 = frictionless
  double recovery_speed = 0.5;   ///< m/s at most when pushing a too-deep contact back out
  /// μ per material pair, symmetric, (materials × materials); empty: frictionless.
  Eigen::MatrixXd mu;
};

class ContactRows final : public RowProducer {
 public:
  /// `bindings[body id]` for every body of the CollisionWorld. \throws std::invalid_argument on a
  /// binding with a system but no frames, a non-square or negative/non-finite μ table.
  ContactRows(std::vector<BodyBinding> bindings, const ContactOptions& options = {});
  const char* name() const override { return "contacts"; }
  /// The contacts of the latest query (copied into preallocated storage; capacity grows here, not in
  /// addRows).
  void setContacts(const collision::ContactSet& set);
  void addRows(int id, double dt, RowSet& rows) override;
  void solved(int id, const RowSet& rows) override;

  BodyBinding& binding(int body) { return bindings_.at(body); }
  /// μ between two bodies (their materials' entry of the table; 0 without friction).
  double friction(int body_a, int body_b) const {
    if (options_.mu.size() == 0 || options_.friction_edges == 0) return 0.0;
    return options_.mu(bindings_.at(static_cast<std::size_t>(body_a)).material, bindings_.at(static_cast<std::size_t>(body_b)).material);
  }
  const std::vector<collision::Contact>& contacts() const { return contacts_; }
  /// Per contact of contacts(), after the last solve: re-evaluated distance (after margins), normal
  /// force λ (N), friction magnitude (N), world point (midpoint of the witness points).
  struct State {
    double distance = 0, normal_force = 0, friction_force = 0;
    math::Vector3 point = math::Vector3::Zero();
    int row = -1;
  };
  const std::vector<State>& states() const { return states_; }
  /// Deepest penetration of the real geometry at the last addRows: max(0, −(d + margin_a + margin_b)) (m).
  double maxPenetration() const { return max_penetration_; }

 private:
  std::vector<BodyBinding> bindings_;
  ContactOptions options_;
  std::vector<collision::Contact> contacts_;
  std::vector<State> states_;
  std::vector<Eigen::Matrix3Xd> Ja_, Jb_;  // per system: point Jacobians of side a / b (3 × nv_s)
  double max_penetration_ = 0;
};

}  // namespace mannequin::constraints
