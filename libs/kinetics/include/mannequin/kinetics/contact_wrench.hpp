#pragma once
/// \file contact_wrench.hpp
/// \brief A wrench shared among frictional point contacts, with the part they cannot carry reported.
///
/// The body needs an external wrench W (inverse dynamics: its rate of momentum minus its weight and
/// any known loads). Point contact i at p_i with normal n_i (the direction the environment pushes the
/// body) and friction μ_i carries a force in its linearised friction cone, f_i = Σ_k x_ik a_ik with
/// x_ik ≥ 0 on the cone's edges a_ik = normalise(n_i + μ_i (cos θ_k t1 + sin θ_k t2)), θ_k = 2πk/m_a
/// (thesis 3.56–3.58). The equilibrium G x = W (3.52, 3.59; G's column of edge k of contact i is
/// [(p_i − c) × a_ik; a_ik], moments about a reference point c, the CoM) may have no solution: a body in
/// the air, a CoM outside the support, a pull no contact can give. So it is solved in the least-squares
/// sense, as an LCP (thesis 3.1.2) solved by Lemke:
///   min_x ½ ‖S (G x − W)‖² + ½ ε ‖x‖²,  x ≥ 0    ⇔    0 ≤ (GᵀS²G + εI) x − GᵀS²W ⊥ x ≥ 0
/// with S = diag(1/L, 1/L, 1/L, 1, 1, 1) weighing a moment error of L N·m as 1 N of force error. The
/// residual W − G x is the part of the wrench the contacts cannot carry: with ε small it is zero
/// (to ~ε‖x‖) whenever the equilibrium has a solution. All quantities are in the world frame.
#include <vector>

#include "mannequin/lcp/lcp.hpp"
#include "mannequin/math/types.hpp"

namespace mannequin::kinetics {

using math::Vector3;
using math::Vector6;

/// One frictional point contact on the body (world frame).
struct ContactPoint {
  Vector3 point = Vector3::Zero();
  Vector3 normal = Vector3::UnitZ();  ///< the direction the environment pushes the body (normalised here)
  double mu = 0.6;                    ///< Coulomb friction coefficient (≥ 0)
  int joint = -1;                     ///< the model joint whose body it touches (for joint torques); −1: none
};

/// Options of distributeWrench().
struct DistributionOptions {
  int edges = 8;                  ///< m_a, edges per linearised cone (3..64)
  double moment_length_m = 0.1;   ///< L: a moment error of L N·m weighs as 1 N
  double regularization = 1e-8;   ///< ε relative to the largest diagonal entry of GᵀS²G
};

/// The shared wrench.
struct WrenchDistribution {
  lcp::LcpStatus status = lcp::LcpStatus::Invalid;  ///< of the LCP (Solved on success)
  std::vector<Vector3> forces;      ///< per contact: the force on the body (N, world)
  Vector3 residual_force = Vector3::Zero();   ///< W − G x, force part (N)
  Vector3 residual_moment = Vector3::Zero();  ///< W − G x, moment about the reference point (N·m)
};

/// Shares `wrench` (n about `reference`, then f; world) among `contacts` (see the file comment).
/// No contact: everything is residual. \throws std::invalid_argument on a non-finite input, a
/// negative μ or a zero normal (naming the contact) or options out of range.
WrenchDistribution distributeWrench(const Vector6& wrench, const Vector3& reference,
                                    const std::vector<ContactPoint>& contacts, const DistributionOptions& options = {});

}  // namespace mannequin::kinetics
