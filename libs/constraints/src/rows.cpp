#include "mannequin/constraints/rows.hpp"

#include <stdexcept>
#include <string>

namespace mannequin::constraints {

const char* rowSourceName(RowSource s) {
  switch (s) {
    case RowSource::kJointLimit: return "joint_limit";
    case RowSource::kSwing: return "swing";
    case RowSource::kTwist: return "twist";
    case RowSource::kContact: return "contact";
    case RowSource::kBalance: return "balance";
    case RowSource::kGrasp: return "grasp";
    case RowSource::kHinge: return "hinge";
    case RowSource::kGuide: return "guide";
    case RowSource::kOther: return "other";
  }
  return "other";
}

// Every Jacobian matrix has one extra row past its capacity: a sink that jacobian()/tangent() hand
// out for an invalid row (e.g. a dropped one, −1), so a careless producer never writes out of bounds.
RowSet::RowSet(const std::vector<int>& system_nv, int max_rows, int max_friction_rows, int max_edges)
    : max_edges_(max_edges) {
  if (system_nv.empty() || system_nv.size() > 64)
    throw std::invalid_argument("RowSet: needs 1 to 64 systems, got " + std::to_string(system_nv.size()));
  if (max_rows < 0 || max_friction_rows < 0 || max_friction_rows > max_rows || max_edges < 1)
    throw std::invalid_argument("RowSet: needs max_rows >= 0, 0 <= max_friction_rows <= max_rows, max_edges >= 1");
  for (std::size_t s = 0; s < system_nv.size(); ++s) {
    if (system_nv[s] < 0) throw std::invalid_argument("RowSet: system " + std::to_string(s) + " has nv < 0");
    J_.emplace_back(RowMatrix::Zero(max_rows + 1, system_nv[s]));
    T1_.emplace_back(RowMatrix::Zero(max_friction_rows + 1, system_nv[s]));
    T2_.emplace_back(RowMatrix::Zero(max_friction_rows + 1, system_nv[s]));
  }
  info_.resize(static_cast<std::size_t>(max_rows));
  slot_.assign(static_cast<std::size_t>(max_rows), -1);
  touch_.assign(static_cast<std::size_t>(max_rows), 0);
}

void RowSet::clear() {
  n_ = 0;
  nf_ = 0;
}

int RowSet::add(const RowInfo& info) {
  const bool friction = info.kind == RowKind::kUnilateral && info.friction_edges > 0 && info.mu > 0.0;
  const int max_friction = static_cast<int>(T1_[0].rows()) - 1;
  if (n_ >= capacity() || (friction && (nf_ >= max_friction || info.friction_edges > max_edges_))) {
    ++dropped_;
    return -1;
  }
  const int r = n_++;
  const auto ur = static_cast<std::size_t>(r);
  info_[ur] = info;
  info_[ur].lambda = 0.0;
  info_[ur].friction = 0.0;
  if (!friction) info_[ur].friction_edges = 0;
  touch_[ur] = 0;
  slot_[ur] = friction ? nf_++ : -1;
  for (std::size_t s = 0; s < J_.size(); ++s) {
    J_[s].row(r).setZero();
    if (friction) {
      T1_[s].row(slot_[ur]).setZero();
      T2_[s].row(slot_[ur]).setZero();
    }
  }
  return r;
}

RowSet::RowBlock RowSet::jacobian(int r, int s) {
  RowMatrix& J = J_[static_cast<std::size_t>(s)];
  if (r < 0 || r >= n_) return J.row(J.rows() - 1);  // the sink
  touch_[static_cast<std::size_t>(r)] |= std::uint64_t{1} << s;
  return J.row(r);
}

RowSet::RowBlock RowSet::tangent(int r, int s, int which) {
  RowMatrix& T = which == 0 ? T1_[static_cast<std::size_t>(s)] : T2_[static_cast<std::size_t>(s)];
  if (r < 0 || r >= n_ || slot_[static_cast<std::size_t>(r)] < 0) return T.row(T.rows() - 1);  // the sink
  touch_[static_cast<std::size_t>(r)] |= std::uint64_t{1} << s;
  return T.row(slot_[static_cast<std::size_t>(r)]);
}

}  // namespace mannequin::constraints
