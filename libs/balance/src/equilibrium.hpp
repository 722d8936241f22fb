#pragma once
// Internal: the parts the static (3.69) and the variational (3.107) balance problems share — the
// linearised cones (3.56–3.58), the static equilibrium G X = W (3.59), the margins' W' (3.72–3.95) and the
// criterion's force blocks (3.69). World frame; wrenches (moment about the origin, force).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "mannequin/balance/static_balance.hpp"

namespace mannequin::balance::detail {

struct Equilibrium {
  Eigen::MatrixXd edges;     // 3 × nf, unit edge directions
  Eigen::MatrixXd G;         // 6 × (nf + 3): edge columns [p × a; a], CoM columns [−[m g]×; 0]
  Eigen::VectorXd W;         // 6: [0; −m g] − W_ext
  Eigen::VectorXd Wm;        // 6: W' = W + G_f(ν'_f − ν_f) (= W without margins)
  Eigen::VectorXd f_desired; // nf: each contact's desired force as least-norm edge forces
  Eigen::VectorXd nu_f, nu_prime_f;  // nf: ν_f, ν'_f (zeros without margins)

  /// edges, G, W, f_desired (and Wm = W, ν = 0).
  void build(const std::vector<PointContact>& contacts, int ma, double mass, const math::Vector3& gravity,
             const math::Vector6& external_wrench);
  /// ν_f = (G⁺W)_f, ν'_f = min(ν_f, ν'_f_i) over the margins (3.83, 3.86, 3.95), W' (3.89). With
  /// `com_free` false the CoM is given: the pseudo-inverse is G_f's and `rhs` is W − G_x x_com.
  void margins(const std::vector<math::Vector3>& com_margins, const std::vector<math::Vector6>& force_margins,
               bool com_free = true, const Eigen::VectorXd* rhs = nullptr);
  /// B_i = w_f I + α a_iᵀ(I − n nᵀ)a_i stacked (nf × m_a).
  void forceWeights(const std::vector<PointContact>& contacts, int ma, double force_weight, double alpha,
                    Eigen::MatrixXd& B) const;
};

/// "" when the contacts, margins and common fields are valid, else what is wrong (named).
std::string validateCommon(const std::vector<PointContact>& contacts, int edges, double force_weight, double alpha,
                           const math::Vector3& gravity, const math::Vector6& external_wrench,
                           const std::vector<math::Vector3>& com_margins, const std::vector<math::Vector6>& force_margins);

std::string num(double v);
std::string vec(const math::Vector3& v);

}  // namespace mannequin::balance::detail
