#include "mannequin/constraints/contacts.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mannequin::constraints {

void MannequinFrames::pointJacobian(int joint, const math::Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const {
  J.setZero();
  // ṗ = Σ_k (v_k + ω_k × p) q̇_k over the joints supporting `joint` (Data::J: world spatial columns)
  for (const int k : model_->support[static_cast<std::size_t>(joint)]) {
    const skeleton::Joint& jk = model_->joints[static_cast<std::size_t>(k)];
    for (int c = 0; c < jk.nv; ++c) {
      const int col = jk.idx_v + c;
      const auto w = data_->J.col(col).head<3>();
      const auto v = data_->J.col(col).tail<3>();
      J.col(col) = v + w.cross(p);
    }
  }
}

ContactRows::ContactRows(std::vector<BodyBinding> bindings, const ContactOptions& options)
    : bindings_(std::move(bindings)), options_(options) {
  for (std::size_t i = 0; i < bindings_.size(); ++i) {
    const BodyBinding& b = bindings_[i];
    if (b.system >= 0 && b.frames == nullptr)
      throw std::invalid_argument("contacts: body " + std::to_string(i) + " has a system but no frames");
    if (!(b.margin >= 0) || !std::isfinite(b.margin))
      throw std::invalid_argument("contacts: body " + std::to_string(i) + " has a bad margin");
  }
  const Eigen::MatrixXd& mu = options_.mu;
  if (mu.size() > 0) {
    if (mu.rows() != mu.cols()) throw std::invalid_argument("contacts: the friction table must be square");
    if (!mu.allFinite() || (mu.array() < 0).any()) throw std::invalid_argument("contacts: μ must be finite and >= 0");
    for (const BodyBinding& b : bindings_)
      if (b.material < 0 || b.material >= mu.rows())
        throw std::invalid_argument("contacts: material " + std::to_string(b.material) + " outside the friction table");
  }
  if (options_.friction_edges < 0 || options_.friction_edges > 64)
    throw std::invalid_argument("contacts: friction_edges must be in [0, 64]");
  if (!(options_.recovery_speed >= 0) || !std::isfinite(options_.recovery_speed))
    throw std::invalid_argument("contacts: recovery_speed must be finite and >= 0");
}

void ContactRows::setContacts(const collision::ContactSet& set) {
  contacts_.assign(set.contacts.begin(), set.contacts.end());  // keeps capacity once grown
  if (states_.size() < contacts_.size()) states_.resize(contacts_.size());
}

namespace {
// t1, t2: an orthonormal basis of the plane ⟂ n
void tangentBasis(const math::Vector3& n, math::Vector3& t1, math::Vector3& t2) {
  const math::Vector3 a = std::abs(n.x()) < 0.9 ? math::Vector3::UnitX() : math::Vector3::UnitY();
  t1 = (a - a.dot(n) * n).normalized();
  t2 = n.cross(t1);
}
}  // namespace

void ContactRows::addRows(int id, double /*dt*/, RowSet& rows) {
  max_penetration_ = 0;
  const int n = static_cast<int>(contacts_.size());
  for (int i = 0; i < n; ++i) {
    const collision::Contact& c = contacts_[static_cast<std::size_t>(i)];
    State& st = states_[static_cast<std::size_t>(i)];
    st = State{};
    if (c.body_a < 0 || c.body_b < 0 || c.body_a >= static_cast<int>(bindings_.size()) ||
        c.body_b >= static_cast<int>(bindings_.size()))
      continue;
    const BodyBinding& A = bindings_[static_cast<std::size_t>(c.body_a)];
    const BodyBinding& B = bindings_[static_cast<std::size_t>(c.body_b)];
    if (A.system < 0 && B.system < 0) continue;  // static–static: nothing moves
    // witness points at q_k (3.9): p = oMb · P
    const math::SE3& oMa = A.frames ? A.frames->pose(A.local) : A.static_pose;
    const math::SE3& oMb = B.frames ? B.frames->pose(B.local) : B.static_pose;
    const math::Vector3 pa = oMa.act(c.point_a);
    const math::Vector3 pb = oMb.act(c.point_b);
    const math::Vector3& nrm = c.normal;
    const double d = nrm.dot(pb - pa);
    if (!std::isfinite(d)) continue;
    st.distance = d;
    st.point = 0.5 * (pa + pb);
    max_penetration_ = std::max(max_penetration_, -(d + A.margin + B.margin));
    RowInfo info;
    info.kind = RowKind::kUnilateral;
    info.source = RowSource::kContact;
    info.producer = id;
    info.tag = i;
    info.distance = d;
    info.recovery_speed = options_.recovery_speed;
    info.system_a = A.system;
    info.system_b = B.system;
    const double mu = options_.mu.size() > 0 ? options_.mu(A.material, B.material) : 0.0;
    if (mu > 0 && options_.friction_edges > 0) {
      info.mu = mu;
      info.friction_edges = options_.friction_edges;
    }
    int r = rows.add(info);
    if (r < 0 && info.friction_edges > 0) {  // no friction slot left: keep the normal row at least
      info.mu = 0;
      info.friction_edges = 0;
      r = rows.add(info);
    }
    if (r < 0) continue;
    st.row = r;
    math::Vector3 t1, t2;
    tangentBasis(nrm, t1, t2);
    const bool friction = rows.frictionSlot(r) >= 0;
    // J = nᵀ(J_pb − J_pa) (3.10–3.15), split on the systems of a and b
    for (int side = 0; side < 2; ++side) {
      const BodyBinding& Bd = side == 0 ? A : B;
      if (Bd.system < 0) continue;
      const double sign = side == 0 ? -1.0 : 1.0;
      const int nv = rows.systemNv(Bd.system);
      auto& buffers = side == 0 ? Ja_ : Jb_;
      if (static_cast<int>(buffers.size()) <= Bd.system) buffers.resize(static_cast<std::size_t>(Bd.system) + 1);
      Eigen::Matrix3Xd& Jp = buffers[static_cast<std::size_t>(Bd.system)];
      if (Jp.cols() != nv) Jp.resize(3, nv);  // once per system: warm-up
      Bd.frames->pointJacobian(Bd.local, side == 0 ? pa : pb, Jp);
      // two bodies of the same system (self contact): the rows add up
      rows.jacobian(r, Bd.system).noalias() += sign * (nrm.transpose() * Jp);
      if (friction) {
        rows.tangent(r, Bd.system, 0).noalias() += sign * (t1.transpose() * Jp);
        rows.tangent(r, Bd.system, 1).noalias() += sign * (t2.transpose() * Jp);
      }
    }
    // a row no velocity can change (its Jacobian vanishes, e.g. two points of one chain moving
    // together) constrains nothing and, deeper than the margins, would make the LCP infeasible: its
    // force would be unbounded. It is dropped (the pair is still reported).
    double jn = 0;
    for (const int sys : {A.system, B.system})
      if (sys >= 0) jn += rows.jacobian(r, sys).squaredNorm();
    if (jn < 1e-18) {
      rows.info(r).distance = std::max(0.0, d);
      rows.info(r).recovery_speed = 0.0;
      rows.info(r).kind = RowKind::kUnilateral;
      st.row = -1;
      rows.info(r).tag = -1;
      rows.info(r).mu = 0;
    }
  }
}

void ContactRows::solved(int /*id*/, const RowSet& rows) {
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    State& st = states_[i];
    if (st.row < 0) continue;
    st.normal_force = rows.info(st.row).lambda;
    st.friction_force = rows.info(st.row).friction;
  }
}

}  // namespace mannequin::constraints
