#include "equilibrium.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mannequin/math/so3.hpp"

namespace mannequin::balance::detail {

std::string vec(const math::Vector3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", v.x(), v.y(), v.z());
  return buf;
}
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string validateCommon(const std::vector<PointContact>& contacts, int edges, double force_weight, double alpha,
                           const math::Vector3& gravity, const math::Vector6& external_wrench,
                           const std::vector<math::Vector3>& com_margins, const std::vector<math::Vector6>& force_margins) {
  if (!gravity.allFinite() || gravity.norm() < 1e-9) return "gravity must be finite and non-zero (got " + vec(gravity) + ")";
  if (!external_wrench.allFinite()) return "external_wrench has a NaN or Inf";
  if (edges < 3 || edges > 64) return "edges per cone must be in 3..64 (got " + std::to_string(edges) + ")";
  if (!(force_weight > 0) || !std::isfinite(force_weight)) return "force_weight must be > 0 and finite";
  if (!(alpha >= 0) || !std::isfinite(alpha)) return "alpha must be >= 0 and finite";
  if (contacts.empty()) return "no contact: nothing can carry the weight";
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const PointContact& c = contacts[i];
    const std::string at = "contact " + std::to_string(i) + ": ";
    if (!c.point.allFinite()) return at + "point has a NaN or Inf";
    if (!c.normal.allFinite() || c.normal.norm() < 1e-9) return at + "normal must be finite and non-zero (got " + vec(c.normal) + ")";
    if (!(c.mu >= 0) || !std::isfinite(c.mu)) return at + "mu must be >= 0 and finite (got " + num(c.mu) + ")";
    if (!c.desired_force.allFinite()) return at + "desired_force has a NaN or Inf";
  }
  for (std::size_t i = 0; i < com_margins.size(); ++i)
    if (!com_margins[i].allFinite()) return "com_margins[" + std::to_string(i) + "] has a NaN or Inf";
  for (std::size_t i = 0; i < force_margins.size(); ++i)
    if (!force_margins[i].allFinite()) return "force_margins[" + std::to_string(i) + "] has a NaN or Inf";
  return "";
}

void Equilibrium::build(const std::vector<PointContact>& contacts, int ma, double mass, const math::Vector3& gravity,
                        const math::Vector6& external_wrench) {
  const int mc = static_cast<int>(contacts.size()), nf = mc * ma;
  // the linearised cones (3.56–3.58): a_ik = (n + μ(cos θ_k t1 + sin θ_k t2)) normalised
  edges.resize(3, nf);
  for (int i = 0; i < mc; ++i) {
    const PointContact& c = contacts[static_cast<std::size_t>(i)];
    const math::Vector3 n = c.normal.normalized();
    // tangent basis: t1 ⟂ n along the axis least aligned with n, t2 = n × t1
    const math::Vector3 ref = std::abs(n.x()) < 0.9 ? math::Vector3::UnitX() : math::Vector3::UnitY();
    const math::Vector3 t1 = (ref - n * n.dot(ref)).normalized();
    const math::Vector3 t2 = n.cross(t1);
    for (int k = 0; k < ma; ++k) {
      const double th = 2.0 * M_PI * k / ma;
      edges.col(i * ma + k) = (n + c.mu * (std::cos(th) * t1 + std::sin(th) * t2)).normalized();
    }
  }
  // G and W (3.59)
  const math::Vector3 mg = mass * gravity;
  G.resize(6, nf + 3);
  for (int i = 0; i < mc; ++i)
    for (int k = 0; k < ma; ++k) {
      const int j = i * ma + k;
      const math::Vector3 a = edges.col(j);
      G.block<3, 1>(0, j) = contacts[static_cast<std::size_t>(i)].point.cross(a);
      G.block<3, 1>(3, j) = a;
    }
  G.block<3, 3>(0, nf) = -math::hat(mg);
  G.block<3, 3>(3, nf).setZero();
  W.resize(6);
  W.head<3>().setZero();
  W.tail<3>() = -mg;
  W -= external_wrench;
  Wm = W;
  nu_f.setZero(nf);
  nu_prime_f.setZero(nf);
  // desired edge forces: least-norm f^dis with a_i f^dis = f_d
  f_desired.resize(nf);
  for (int i = 0; i < mc; ++i) {
    const math::Vector3& fd = contacts[static_cast<std::size_t>(i)].desired_force;
    if (fd.isZero(0.0)) {
      f_desired.segment(i * ma, ma).setZero();
    } else {
      const Eigen::MatrixXd A = edges.middleCols(i * ma, ma);
      f_desired.segment(i * ma, ma) = A.transpose() * (A * A.transpose()).ldlt().solve(fd);
    }
  }
}

void Equilibrium::margins(const std::vector<math::Vector3>& com_margins, const std::vector<math::Vector6>& force_margins,
                          bool com_free, const Eigen::VectorXd* rhs) {
  const Eigen::Index nf = G.cols() - 3;
  if (com_margins.empty() && force_margins.empty()) return;
  const Eigen::VectorXd& Wu = rhs != nullptr ? *rhs : W;
  // G⁺ = Gᵀ(GGᵀ)⁻¹ of the unknowns' columns: G (forces and CoM) or G_f (the CoM given)
  const Eigen::Matrix<double, 6, 6> S0 = com_free ? Eigen::Matrix<double, 6, 6>(G * G.transpose())
                                                  : Eigen::Matrix<double, 6, 6>(G.leftCols(nf) * G.leftCols(nf).transpose());
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> S0_llt(S0);
  const Eigen::Matrix<double, 6, 1> s0w = S0_llt.solve(Eigen::Matrix<double, 6, 1>(Wu));
  nu_f = G.leftCols(nf).transpose() * s0w;
  nu_prime_f = nu_f;
  if (!com_margins.empty()) {
    // Π_fx = −G_fᵀ S0⁻¹ G_x, Π_xx = I − G_xᵀ S0⁻¹ G_x; Π_f T (Δx; 0) = Π_fx Π_xx⁺ Δx
    const Eigen::Matrix<double, 6, 3> s0gx = S0_llt.solve(Eigen::Matrix<double, 6, 3>(G.rightCols<3>()));
    const Eigen::MatrixXd Pi_fx = -G.leftCols(nf).transpose() * s0gx;
    const math::Matrix3 Pi_xx = math::Matrix3::Identity() - G.rightCols<3>().transpose() * s0gx;
    const Eigen::SelfAdjointEigenSolver<math::Matrix3> es(Pi_xx);
    const double smax = std::max(es.eigenvalues().maxCoeff(), 1e-300);
    math::Matrix3 Pinv = math::Matrix3::Zero();
    for (int k = 0; k < 3; ++k)
      if (es.eigenvalues()[k] > 1e-9 * smax)
        Pinv += es.eigenvectors().col(k) * es.eigenvectors().col(k).transpose() / es.eigenvalues()[k];
    for (const math::Vector3& dx : com_margins) nu_prime_f = nu_prime_f.cwiseMin(nu_f + Pi_fx * (Pinv * dx));
  }
  for (const math::Vector6& D : force_margins) {
    const Eigen::Matrix<double, 6, 1> s = S0_llt.solve(Eigen::Matrix<double, 6, 1>(-D));
    nu_prime_f = nu_prime_f.cwiseMin(nu_f + G.leftCols(nf).transpose() * s);
  }
  Wm = W + G.leftCols(nf) * (nu_prime_f - nu_f);
}

void Equilibrium::forceWeights(const std::vector<PointContact>& contacts, int ma, double force_weight, double alpha,
                               Eigen::MatrixXd& B) const {
  const int mc = static_cast<int>(contacts.size());
  B.resize(mc * ma, ma);
  for (int i = 0; i < mc; ++i) {
    const math::Vector3 nn = contacts[static_cast<std::size_t>(i)].normal.normalized();
    const Eigen::MatrixXd T = (math::Matrix3::Identity() - nn * nn.transpose()) * edges.middleCols(i * ma, ma);
    B.middleRows(i * ma, ma) = force_weight * Eigen::MatrixXd::Identity(ma, ma) + alpha * T.transpose() * T;
  }
}

}  // namespace mannequin::balance::detail
