#pragma once
/// \file balance.hpp
/// \brief Coplanar static balance as one row of the step's LCP (thesis 3.3.2.1, eq. 3.22–3.37,
/// Fig. 4.22): the ground projection of the centre of mass must stay inside the support region.
///
/// Support region (SupportRegion), rebuilt whenever the caller gives the support points (world points
/// where the feet touch the floor) and the floor plane (a point o and a unit normal n, pointing up):
/// - Π: the projection on the floor along n, written in 2-D floor coordinates u = Eᵀ(x − o), E = [e1 e2]
///   an orthonormal basis of the plane (2 × 3 matrix Eᵀ);
/// - the support POLYGON: the 2-D convex hull of the projected points (counter-clockwise about n);
/// - the support ELLIPSE of the thesis ("une ellipse englobant les deux pieds"): centre x_c = the
///   polygon's area centroid, shape from the polygon's second moment of area Σ (its inertia ellipse),
///   Q = Σ⁻¹ scaled so that λ_max(Q) = 1, and δ the smallest scale with every hull vertex inside
///   (δ² = max_v ‖v − x_c‖²_Q): the smallest ellipse of that centre and shape enclosing the polygon
///   (for a rectangle a × b it is the minimum-area enclosing ellipse, semi-axes a/√2, b/√2).
///   With `inscribed` instead, δ is the largest scale inside the polygon (δ = min over edges of
///   h_e / ‖n_e‖_{Q⁻¹}, h_e the edge line's distance from x_c): conservative, CoM inside ⇒ inside the
///   polygon. With λ_max(Q) = 1, δ is the ellipse's semi-minor axis in metres.
///   Degenerate supports (collinear points: a uniform segment's covariance; one point: 0) add
///   (min_radius)² I to Σ; Σ's eigenvalues are floored at min_radius² (sliver polygons); δ ≥ min_radius.
///
/// Distances (BalanceDistance, all from the CoM x_com in the world):
/// - ellipse (3.22):  d(q) = δ² − ‖Π(x_com − x_c)‖²_Q                         (m², > 0 inside)
/// - ellipse_m:       d(q) / (2δ)                                               (m)
///   the ROW's distance: the thesis's d scaled by the constant 1/(2δ) (same constraint, same
///   first-order prediction; metres so that recovery_speed is in m/s). Near the boundary it equals
///   the Euclidean distance on the minor axis and under-estimates it elsewhere (by b/a at most on the
///   major axis).
/// - polygon_m:       signed Euclidean distance of Π(x_com) to the polygon's boundary (m, > 0 inside;
///   a degenerate polygon is a segment or a point: minus the distance to it).
/// sim.world reports `balance_distance_m` = polygon_m (BalanceRows::state().polygon_m): the metric
/// distance to the real support polygon, NaN when there is no support.
///
/// The row (BalanceRows, one mannequin, system s): one kUnilateral row, RowSource::kBalance, with
///   distance d_m = d(q)/(2δ) and Jacobian (3.37, over q̇):
///   J = ∂d_m/∂q̇ = −(1/δ) rᵀ Q Eᵀ J_com,   r = Eᵀ(x_com − x_c) (2-D),  J_com (3 × nv, world) the CoM
///   Jacobian (3.32–3.36), ẋ_com = J_com q̇,
/// the support considered fixed over the step (3.25). No row without support points.
#include <vector>

#include <Eigen/Dense>

#include "mannequin/constraints/solver.hpp"
#include "mannequin/math/types.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::constraints {

using math::Vector3;

struct BalanceOptions {
  bool inscribed = false;       ///< false: the thesis's enclosing ellipse; true: the inscribed one
  double min_radius = 1e-3;     ///< m: regularises degenerate supports (segment, point)
  double recovery_speed = 0.1;  ///< m/s at most when bringing the CoM back into the ellipse
  int max_points = 64;          ///< capacity of the support points (preallocated)
};

/// Signed balance distances of one CoM (see the file comment). NaN when there is no support.
struct BalanceDistance {
  double ellipse = 0.0;    ///< d(q) = δ² − ‖Π(x_com − x_c)‖²_Q (3.22), m² (Q has λ_max = 1)
  double ellipse_m = 0.0;  ///< d(q)/(2δ), m: the row's distance
  double polygon_m = 0.0;  ///< signed distance of Π(x_com) to the polygon boundary, m, > 0 inside
};

/// The support polygon and ellipse on a floor plane, in preallocated storage.
class SupportRegion {
 public:
  /// Floor z = 0, normal +z. \throws std::invalid_argument on max_points < 1 or a bad min_radius.
  explicit SupportRegion(const BalanceOptions& options = {});

  /// The floor plane: a point on it and its (upward) normal, normalised here.
  /// \throws std::invalid_argument on non-finite values or a zero normal (not for the loop).
  void setFloor(const Vector3& point, const Vector3& normal);
  /// The support points (world, m), projected on the floor. Allocation-free up to max_points. Returns
  /// false (and leaves the region empty) on more than max_points points or a non-finite point;
  /// an empty vector empties the region. Never throws.
  bool setSupport(const std::vector<Vector3>& points);

  bool empty() const { return hull_size_ == 0; }
  /// Hull vertices in 2-D floor coordinates, counter-clockwise about n (size hullSize()).
  int hullSize() const { return hull_size_; }
  const Eigen::Vector2d& hullVertex(int i) const { return pts_[static_cast<std::size_t>(i)]; }
  double area() const { return area_; }

  /// 2-D floor coordinates of a world point: Eᵀ(x − o).
  Eigen::Vector2d project(const Vector3& x) const { return E_.transpose() * (x - origin_); }
  /// Eᵀ (2 × 3) and the floor's unit normal.
  const Eigen::Matrix<double, 3, 2>& basis() const { return E_; }
  const Vector3& normal() const { return normal_; }

  /// Ellipse centre x_c (2-D floor coordinates), metric Q (2 × 2, symmetric, λ_max = 1), scale δ (m).
  const Eigen::Vector2d& centre() const { return centre_; }
  const Eigen::Matrix2d& metric() const { return Q_; }
  double delta() const { return delta_; }

  /// The distances of a CoM (world). NaN everywhere when empty().
  BalanceDistance distance(const Vector3& com) const;
  /// Signed distance of a 2-D floor point to the polygon boundary (m, > 0 inside). NaN when empty().
  double polygonDistance(const Eigen::Vector2d& u) const;

  const BalanceOptions& options() const { return options_; }

 private:
  void fitEllipse();
  BalanceOptions options_;
  Vector3 origin_ = Vector3::Zero(), normal_ = Vector3::UnitZ();
  Eigen::Matrix<double, 3, 2> E_;
  std::vector<Eigen::Vector2d> pts_;  // capacity max_points; [0, hull_size_) the hull after setSupport
  int hull_size_ = 0;
  std::vector<Eigen::Vector2d> stack_;  // scratch of the hull (capacity max_points + 1)
  double area_ = 0.0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d Q_ = Eigen::Matrix2d::Identity();
  double delta_ = 0.0;
};

/// d(q) and the polygon distance of a CoM over a support region (SupportRegion::distance).
inline BalanceDistance balanceDistance(const SupportRegion& support, const Vector3& com) {
  return support.distance(com);
}

/// The balance row of one mannequin (system `system` of the ConstraintSolver).
///
/// Reads, at q_k, the model's Data: oMi (joint poses) and J (world joint Jacobian columns), i.e. after
/// skeleton::computeJointJacobians — control::Controller::data() after computeFreeMotion(). The CoM
/// and its Jacobian (3.28, 3.32–3.36) are computed here from them (the Data is const; Data::com and
/// Data::Jcom are neither read nor needed).
class BalanceRows final : public RowProducer {
 public:
  /// \throws std::invalid_argument on a negative system, a model without mass, or bad options.
  BalanceRows(int system, const skeleton::Model& model, const skeleton::Data& data, const BalanceOptions& options = {});
  const char* name() const override { return "balance"; }

  void setData(const skeleton::Data& data) { data_ = &data; }
  /// See SupportRegion::setFloor (throws) and setSupport (returns false on bad input, never throws).
  void setFloor(const Vector3& point, const Vector3& normal) { support_.setFloor(point, normal); }
  bool setSupport(const std::vector<Vector3>& points) { return support_.setSupport(points); }
  const SupportRegion& support() const { return support_; }

  /// Computes the CoM, its Jacobian, the distances and the row's Jacobian at the Data's q (no row
  /// added). Called by addRows; public for tests and reports. Returns false when there is no support.
  bool evaluate();
  /// Appends the balance row (nothing without support; the state's distances are then NaN).
  void addRows(int id, double dt, RowSet& rows) override;
  void solved(int id, const RowSet& rows) override;

  /// What the last evaluate()/addRows()/solved() found.
  struct State {
    BalanceDistance distance{};   ///< d(q), d_m, polygon distance (NaN without support)
    Vector3 com = Vector3::Zero();  ///< x_com (world, m)
    double lambda = 0.0;          ///< the row's force after the solve (N, along d_m)
    int row = -1;                 ///< index in the RowSet (−1: no row)
  };
  const State& state() const { return state_; }
  /// ∂d_m/∂q̇ (1 × nv) of the last evaluate().
  const Eigen::RowVectorXd& jacobian() const { return J_; }
  /// J_com (3 × nv, world) of the last evaluate().
  const Eigen::Matrix3Xd& comJacobian() const { return Jcom_; }

 private:
  int system_;
  const skeleton::Model* model_;
  const skeleton::Data* data_;
  BalanceOptions options_;
  SupportRegion support_;
  std::vector<double> subtree_mass_;     // constant: Σ m over each joint's subtree
  std::vector<Vector3> subtree_moment_;  // per step: Σ m c over each joint's subtree (world)
  double total_mass_ = 0.0;
  Eigen::Matrix3Xd Jcom_;
  Eigen::RowVectorXd J_;
  State state_;
};

}  // namespace mannequin::constraints
