#include "mannequin/kinetics/kinetics.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "mannequin/skeleton/dynamics.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::kinetics {

KineticsSolver::KineticsSolver(const skeleton::Model& model, KineticsOptions options)
    : model_(model), options_(std::move(options)), data_(model), fext_(model.joints.size(), Vector6::Zero()) {
  if (!options_.gravity.allFinite()) throw std::invalid_argument("KineticsSolver: gravity is not finite");
}

KineticsFrame KineticsSolver::solve(const VectorX& q, const VectorX& v, const VectorX& a,
                                    const std::vector<ContactPoint>& contacts, const std::vector<Load>& loads) {
  if (q.size() != model_.nq || v.size() != model_.nv || a.size() != model_.nv)
    throw std::invalid_argument("KineticsSolver::solve: q, v, a have sizes " + std::to_string(q.size()) + ", " +
                                std::to_string(v.size()) + ", " + std::to_string(a.size()) + "; the model has " +
                                std::to_string(model_.nq));
  if (!q.allFinite() || !v.allFinite() || !a.allFinite())
    throw std::invalid_argument("KineticsSolver::solve: q, v or a is not finite");
  const int nj = static_cast<int>(model_.joints.size());
  std::fill(fext_.begin(), fext_.end(), Vector6::Zero());
  for (std::size_t j = 0; j < loads.size(); ++j) {
    const Load& l = loads[j];
    if (l.joint < 0 || l.joint >= nj)
      throw std::invalid_argument("KineticsSolver::solve: load " + std::to_string(j) + " is on joint " +
                                  std::to_string(l.joint) + ", the model has " + std::to_string(nj));
    if (!l.point.allFinite() || !l.force.allFinite())
      throw std::invalid_argument("KineticsSolver::solve: load " + std::to_string(j) + " is not finite");
    fext_[static_cast<std::size_t>(l.joint)] += skeleton::wrenchAt(l.point, l.force);
  }
  for (std::size_t i = 0; i < contacts.size(); ++i)
    if (contacts[i].joint < -1 || contacts[i].joint >= nj)
      throw std::invalid_argument("KineticsSolver::solve: contact " + std::to_string(i) + " is on joint " +
                                  std::to_string(contacts[i].joint) + ", the model has " + std::to_string(nj));
  KineticsFrame out;
  // 1. the wrench the environment must give, loads included
  skeleton::rnea(model_, data_, q, v, a, options_.gravity, &fext_);
  out.required_wrench = data_.joint_wrench[0];
  // (a model whose root is not a free flyer is held by its root joint: the same wrench)
  out.com = skeleton::centerOfMass(model_, data_);
  // 2. shared among the contacts, about the CoM
  Vector6 about_com;
  about_com << skeleton::momentAbout(out.required_wrench, out.com), out.required_wrench.tail<3>();
  WrenchDistribution shared = distributeWrench(about_com, out.com, contacts, options_.distribution);
  out.status = shared.status;
  out.contact_forces = std::move(shared.forces);
  out.residual_force = shared.residual_force;
  out.residual_moment = shared.residual_moment;
  // 3. joint torques with every external force applied where it acts
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    out.contact_force += out.contact_forces[i];
    const int j = contacts[i].joint >= 0 ? contacts[i].joint : 0;
    fext_[static_cast<std::size_t>(j)] += skeleton::wrenchAt(contacts[i].point, out.contact_forces[i]);
  }
  out.tau = skeleton::rnea(model_, data_, q, v, a, options_.gravity, &fext_);
  return out;
}

KineticsSummary summarize(const std::vector<KineticsFrame>& frames, double weight_n) {
  if (!(weight_n > 0)) throw std::invalid_argument("kinetics::summarize: weight " + std::to_string(weight_n) + " N must be > 0");
  KineticsSummary s;
  s.frames = static_cast<int>(frames.size());
  s.weight_n = weight_n;
  if (frames.empty()) return s;
  double vertical = 0, residual = 0;
  for (const KineticsFrame& f : frames) {
    vertical += f.contact_force.z();
    residual += f.residual_force.norm();
    s.residual_force_peak_n = std::max(s.residual_force_peak_n, f.residual_force.norm());
    s.residual_moment_peak_nm = std::max(s.residual_moment_peak_nm, f.residual_moment.norm());
    s.peak_external_force_n = std::max(s.peak_external_force_n, f.contact_force.norm());
  }
  const double n = static_cast<double>(frames.size());
  s.grf_mean_over_weight = vertical / n / weight_n;
  s.residual_force_mean_n = residual / n;
  return s;
}

}  // namespace mannequin::kinetics
