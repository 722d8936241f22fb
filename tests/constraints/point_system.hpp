#pragma once
// Test systems for the constraint solver, checkable by hand: K points of mass m in `dim`-D with
// first-order dynamics b q̇ = Γ, b = (m/τ) I (nv = dim·K), and producers of rows on them.
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "mannequin/constraints/solver.hpp"

namespace test {

using mannequin::constraints::ConstrainedSystem;
using mannequin::constraints::RowInfo;
using mannequin::constraints::RowKind;
using mannequin::constraints::RowProducer;
using mannequin::constraints::RowSet;

class PointSystem final : public ConstrainedSystem {
 public:
  PointSystem(int dim, int points, double mass, double tau)
      : dim_(dim), m_(mass), tau_(tau), x(Eigen::VectorXd::Zero(dim * points)),
        qdot(Eigen::VectorXd::Zero(dim * points)), qdot_free_(Eigen::VectorXd::Zero(dim * points)),
        factor_(mannequin::math::TreeCholesky::dense(dim * points)),
        applied(Eigen::VectorXd::Zero(dim * points)) {
    factor_.compute((mass / tau) * Eigen::MatrixXd::Identity(dim * points, dim * points));
  }
  int nv() const override { return static_cast<int>(x.size()); }
  const Eigen::VectorXd& qdotFree() const override { return qdot_free_; }
  const mannequin::math::TreeCholesky& frictionFactor() const override { return factor_; }
  bool applyConstraintForce(const Eigen::VectorXd& gamma_c) override {
    applied += gamma_c;
    qdot.noalias() += (tau_ / m_) * gamma_c;
    ++applications;
    return true;
  }
  double b() const { return m_ / tau_; }
  /// Stage 1: q̇_free = b⁻¹ Γ_ext (allocation-free).
  void freeMotion(const Eigen::VectorXd& force) {
    qdot_free_ = (tau_ / m_) * force;
    qdot = qdot_free_;
    applied.setZero();
  }
  /// Stage 3.
  void integrate(double dt) { x.noalias() += dt * qdot; }

  int dim_;
  double m_, tau_;
  Eigen::VectorXd x, qdot;

 private:
  Eigen::VectorXd qdot_free_;
  mannequin::math::TreeCholesky factor_;

 public:
  Eigen::VectorXd applied;  ///< Σ Γ_c of this step
  int applications = 0;
};

/// A fixed plane n·x = 0 under point `point` of system `system` (3-D): one unilateral row
/// d = n·x, J = nᵀ; with mu > 0 a friction cone of `edges` directions with t1, t2 ⟂ n.
class PlaneProducer final : public RowProducer {
 public:
  PlaneProducer(const PointSystem& sys, int system, Eigen::Vector3d normal, double mu = 0.0, int edges = 0,
                int point = 0)
      : sys_(&sys), system_(system), point_(point), n_(normal.normalized()), mu_(mu), edges_(edges) {
    // t1 in the plane spanned by n and x̂ (up-slope direction for a normal tilted about y), t2 = n × t1
    const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
    t1_ = y.cross(n_).normalized();
    t2_ = n_.cross(t1_);
  }
  const char* name() const override { return "plane"; }
  void addRows(int id, double /*dt*/, RowSet& rows) override {
    RowInfo in;
    in.source = mannequin::constraints::RowSource::kContact;
    in.producer = id;
    in.distance = n_.dot(sys_->x.segment<3>(3 * point_));
    in.mu = mu_;
    in.friction_edges = edges_;
    in.system_a = system_;
    row = rows.add(in);
    if (row < 0) return;
    rows.jacobian(row, system_).segment<3>(3 * point_) = n_.transpose();
    if (rows.frictionSlot(row) >= 0) {
      rows.tangent(row, system_, 0).segment<3>(3 * point_) = t1_.transpose();
      rows.tangent(row, system_, 1).segment<3>(3 * point_) = t2_.transpose();
    }
  }
  void solved(int /*id*/, const RowSet& rows) override {
    if (row >= 0) {
      lambda = rows.info(row).lambda;
      friction = rows.info(row).friction;
    }
  }
  const Eigen::Vector3d& t1() const { return t1_; }
  const Eigen::Vector3d& normal() const { return n_; }

  int row = -1;
  double lambda = 0.0, friction = 0.0;

 private:
  const PointSystem* sys_;
  int system_, point_;
  Eigen::Vector3d n_, t1_, t2_;
  double mu_;
  int edges_;
};

}  // namespace test
