#include "mannequin/kinetics/contact_wrench.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mannequin/lcp/lemke.hpp"

namespace mannequin::kinetics {

namespace {

// an orthonormal pair ⟂ n
void tangents(const Vector3& n, Vector3& t1, Vector3& t2) {
  const Vector3 seed = std::abs(n.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY();
  t1 = (seed - seed.dot(n) * n).normalized();
  t2 = n.cross(t1);
}
}  // namespace

WrenchDistribution distributeWrench(const Vector6& wrench, const Vector3& reference,
                                    const std::vector<ContactPoint>& contacts, const DistributionOptions& options) {
  if (!wrench.allFinite() || !reference.allFinite())
    throw std::invalid_argument("distributeWrench: the wrench or the reference point is not finite");
  if (options.edges < 3 || options.edges > 64)
    throw std::invalid_argument("distributeWrench: edges " + std::to_string(options.edges) + " outside 3..64");
  if (!(options.moment_length_m > 0) || !(options.regularization > 0))
    throw std::invalid_argument("distributeWrench: moment_length_m and regularization must be > 0");
  WrenchDistribution out;
  out.forces.assign(contacts.size(), Vector3::Zero());
  const int ma = options.edges;
  const int n = static_cast<int>(contacts.size()) * ma;
  if (n == 0) {
    out.status = lcp::LcpStatus::Solved;
    out.residual_moment = wrench.head<3>();
    out.residual_force = wrench.tail<3>();
    return out;
  }
  // G (6 × n): the edges' unit wrenches about the reference point; rows scaled by S
  Eigen::MatrixXd G(6, n);
  std::vector<Vector3> edge(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const ContactPoint& c = contacts[i];
    const std::string which = "distributeWrench: contact " + std::to_string(i);
    if (!c.point.allFinite() || !c.normal.allFinite() || !std::isfinite(c.mu))
      throw std::invalid_argument(which + " is not finite");
    if (c.mu < 0) throw std::invalid_argument(which + " has a negative friction coefficient");
    if (c.normal.norm() < 1e-9) throw std::invalid_argument(which + " has a zero normal");
    const Vector3 nrm = c.normal.normalized();
    Vector3 t1, t2;
    tangents(nrm, t1, t2);
    const Vector3 r = c.point - reference;
    for (int k = 0; k < ma; ++k) {
      const double th = 2 * std::numbers::pi * k / ma;
      const Vector3 a = (nrm + c.mu * (std::cos(th) * t1 + std::sin(th) * t2)).normalized();
      const int col = static_cast<int>(i) * ma + k;
      edge[static_cast<std::size_t>(col)] = a;
      G.col(col) << r.cross(a) / options.moment_length_m, a;
    }
  }
  Vector6 Ws = wrench;
  Ws.head<3>() /= options.moment_length_m;
  lcp::LcpProblem problem;
  problem.M = G.transpose() * G;
  const double eps = options.regularization * problem.M.diagonal().maxCoeff();
  problem.M.diagonal().array() += eps;
  problem.q = -G.transpose() * Ws;
  lcp::LemkeWorkspace workspace(n);
  const lcp::LcpResult result = lcp::solveLemke(problem, workspace);
  out.status = result.status;
  if (result.status != lcp::LcpStatus::Solved) {
    out.residual_moment = wrench.head<3>();
    out.residual_force = wrench.tail<3>();
    return out;
  }
  for (int col = 0; col < n; ++col)
    out.forces[static_cast<std::size_t>(col / ma)] += result.z(col) * edge[static_cast<std::size_t>(col)];
  const Vector6 carried = G * result.z;
  out.residual_moment = wrench.head<3>() - carried.head<3>() * options.moment_length_m;
  out.residual_force = wrench.tail<3>() - carried.tail<3>();
  return out;
}

}  // namespace mannequin::kinetics
