#include "mannequin/constraints/objects.hpp"

#include <cmath>
#include <stdexcept>

namespace mannequin::constraints {

using math::Matrix3;
using math::SE3;
using math::Vector3;

namespace {

bool positiveFinite(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

RigidObject::RigidObject(const RigidObjectSpec& spec)
    : name_(spec.name),
      hinged_(spec.hinge.has_value()),
      mass_(spec.mass),
      tau_(spec.time_constant),
      inertia_(spec.inertia),
      pose0_(spec.pose),
      pose_(spec.pose) {
  const std::string who = "RigidObject '" + name_ + "': ";
  if (!positiveFinite(mass_)) throw std::invalid_argument(who + "mass must be > 0 (kg), got " + std::to_string(mass_));
  if (!positiveFinite(tau_))
    throw std::invalid_argument(who + "time_constant must be > 0 (s), got " + std::to_string(tau_));
  for (int i = 0; i < 3; ++i)
    if (!positiveFinite(inertia_[i])) throw std::invalid_argument(who + "inertia must be > 0 (kg·m²)");
  if (!spec.pose.allFinite() || !math::isRotation(spec.pose.R, 1e-6))
    throw std::invalid_argument(who + "pose is not a finite rigid transform");
  if (hinged_) {
    hinge_ = *spec.hinge;
    const double n = hinge_.axis.norm();
    if (!std::isfinite(n) || n < 1e-9 || !hinge_.point.allFinite())
      throw std::invalid_argument(who + "hinge axis must be non-zero and finite, point finite");
    hinge_.axis /= n;
    if (std::isnan(hinge_.lower) || std::isnan(hinge_.upper) || hinge_.lower > 0.0 || hinge_.upper < 0.0)
      throw std::invalid_argument(who + "hinge limits must satisfy lower <= 0 <= upper (angle 0 = initial pose)");
    const Vector3& a = hinge_.axis;
    const Vector3 r = pose0_.p - hinge_.point;
    const double Ia = a.dot(pose0_.R * inertia_.asDiagonal() * pose0_.R.transpose() * a) + mass_ * a.cross(r).squaredNorm();
    b_ = Eigen::MatrixXd::Constant(1, 1, Ia / tau_);
  } else {
    b_ = Eigen::MatrixXd::Zero(6, 6);
    b_.diagonal().head<3>() = inertia_ / tau_;
    b_.diagonal().tail<3>().setConstant(mass_ / tau_);
  }
  b_inv_ = b_.diagonal().cwiseInverse();
  factor_ = math::TreeCholesky(std::vector<int>(static_cast<std::size_t>(nv()), -1));
  factor_.compute(b_);
  qdot_free_ = Eigen::VectorXd::Zero(nv());
  qdot_ = Eigen::VectorXd::Zero(nv());
}

void RigidObject::addForce(const Vector3& point, const Vector3& force) {
  ext_force_ += force;
  ext_moment_ += (point - pose_.p).cross(force);
}

void RigidObject::computeFreeMotion(const Vector3& gravity, double /*dt*/) {
  const Vector3 f = mass_ * gravity + ext_force_;  // world, at the centre of mass
  if (hinged_) {
    const Vector3 r = pose_.p - hinge_.point;
    qdot_free_[0] = b_inv_[0] * hinge_.axis.dot(ext_moment_ + r.cross(f));
  } else {
    qdot_free_.head<3>() = b_inv_.head<3>().cwiseProduct(pose_.R.transpose() * ext_moment_);
    qdot_free_.tail<3>() = b_inv_.tail<3>().cwiseProduct(pose_.R.transpose() * f);
  }
  qdot_ = qdot_free_;
}

bool RigidObject::applyConstraintForce(const Eigen::VectorXd& gamma_c) {
  if (gamma_c.size() != qdot_.size() || !gamma_c.allFinite()) return false;  // refused: ν stays
  qdot_ += b_inv_.cwiseProduct(gamma_c);
  return true;
}

void RigidObject::integrate(double dt) {
  if (hinged_) {
    theta_ += dt * qdot_[0];
    updateHingePose();
  } else {
    math::Vector6 step;
    step = dt * qdot_.head<6>();
    pose_ = pose_ * math::expSE3(step);
  }
  ext_force_.setZero();
  ext_moment_.setZero();
}

void RigidObject::updateHingePose() {
  const Matrix3 Rot = Eigen::AngleAxisd(theta_, hinge_.axis).toRotationMatrix();
  pose_ = SE3(Rot, hinge_.point - Rot * hinge_.point) * pose0_;
}

void RigidObject::setPose(const SE3& H) {
  if (hinged_) return;  // a hinged body moves by its angle only
  pose_ = H;
  qdot_.setZero();
  qdot_free_.setZero();
  ext_force_.setZero();
  ext_moment_.setZero();
}

void RigidObject::setAngle(double theta) {
  if (!hinged_) return;
  theta_ = theta;
  updateHingePose();
  qdot_.setZero();
  qdot_free_.setZero();
  ext_force_.setZero();
  ext_moment_.setZero();
}

const SE3& RigidObject::pose(int /*local*/) const { return pose_; }

void RigidObject::pointJacobian(int /*local*/, const Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const {
  if (hinged_) {
    J.col(0) = hinge_.axis.cross(p - hinge_.point);
  } else {
    const Vector3 pl = pose_.R.transpose() * (p - pose_.p);
    J.leftCols<3>() = -pose_.R * math::hat(pl);
    J.rightCols<3>() = pose_.R;
  }
}

Vector3 RigidObject::pointVelocity(const Vector3& p) const {
  if (hinged_) return qdot_[0] * hinge_.axis.cross(p - hinge_.point);
  const Vector3 pl = pose_.R.transpose() * (p - pose_.p);
  return pose_.R * (qdot_.tail<3>() + qdot_.head<3>().cross(pl));
}

std::vector<RigidObject> makeObjects(const collision::SceneSpec& scene, std::vector<int>* body_index,
                                     double default_time_constant) {
  std::vector<RigidObject> objects;
  if (body_index) body_index->clear();
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const collision::BodySpec& b = scene.bodies[i];
    if (!b.movable || !b.dynamics) continue;
    RigidObjectSpec spec;
    spec.name = b.name;
    spec.pose = b.pose;
    spec.mass = b.dynamics->mass;
    spec.inertia = b.dynamics->inertia;
    spec.time_constant = b.dynamics->time_constant > 0 ? b.dynamics->time_constant : default_time_constant;
    spec.hinge = b.dynamics->hinge;
    objects.emplace_back(spec);
    if (body_index) body_index->push_back(static_cast<int>(i));
  }
  return objects;
}

// ---------------------------------------------------------------------------------------------
HingeLimitRows::HingeLimitRows(std::vector<Entry> objects, double activation, double recovery_speed)
    : activation_(activation), recovery_speed_(recovery_speed) {
  if (!(activation > 0.0) || !(recovery_speed > 0.0))
    throw std::invalid_argument("HingeLimitRows: activation and recovery_speed must be > 0");
  for (const Entry& e : objects) {
    if (!e.object || e.system < 0) throw std::invalid_argument("HingeLimitRows: null object or negative system");
    if (e.object->hinged() &&
        (std::isfinite(e.object->hinge().lower) || std::isfinite(e.object->hinge().upper)))
      objects_.push_back(e);
  }
}

void HingeLimitRows::addRows(int id, double /*dt*/, constraints::RowSet& rows) {
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const RigidObject& o = *objects_[i].object;
    const double theta = o.angle();
    for (int side = 0; side < 2; ++side) {
      const double limit = side == 0 ? o.hinge().lower : o.hinge().upper;
      if (!std::isfinite(limit)) continue;
      const double d = side == 0 ? theta - limit : limit - theta;
      if (d > activation_) continue;
      constraints::RowInfo info;
      info.kind = constraints::RowKind::kUnilateral;
      info.source = constraints::RowSource::kHinge;
      info.producer = id;
      info.tag = static_cast<int>(2 * i + side);
      info.distance = d;
      info.recovery_speed = recovery_speed_;
      info.system_a = objects_[i].system;
      const int r = rows.add(info);
      if (r < 0) continue;
      rows.jacobian(r, objects_[i].system)(0) = side == 0 ? 1.0 : -1.0;
    }
  }
}

// ---------------------------------------------------------------------------------------------
GraspRows::GraspRows(std::vector<const RigidObject*> objects, std::vector<int> object_systems, int max_nv,
                     int max_grasps, double recovery_speed)
    : objects_(std::move(objects)), systems_(std::move(object_systems)), recovery_speed_(recovery_speed) {
  if (objects_.size() != systems_.size())
    throw std::invalid_argument("GraspRows: objects and object_systems differ in size");
  for (std::size_t i = 0; i < objects_.size(); ++i)
    if (!objects_[i] || systems_[i] < 0) throw std::invalid_argument("GraspRows: null object or negative system");
  if (max_nv < 1 || max_grasps < 1) throw std::invalid_argument("GraspRows: max_nv and max_grasps must be >= 1");
  if (!(recovery_speed > 0.0)) throw std::invalid_argument("GraspRows: recovery_speed must be > 0");
  grasps_.resize(static_cast<std::size_t>(max_grasps));
  const int n = std::max(max_nv, 6);
  Jp_obj_.setZero(3, n);
  Jw_obj_.setZero(3, n);
  Jp_hand_.setZero(3, n);
  Jw_hand_.setZero(3, n);
  J0_.setZero(3, n);
  J1_.setZero(3, n);
}

int GraspRows::grasp(const Hand& hand, int object) {
  if (object < 0 || object >= static_cast<int>(objects_.size()) || !hand.frames || hand.system < 0) return -1;
  if (hand.system == systems_[object]) return -1;
  for (const Grasp& gr : grasps_)  // this hand holds it already (several hands may hold one object)
    if (gr.active && gr.object == object && gr.hand.system == hand.system && gr.hand.frames == hand.frames &&
        gr.hand.local == hand.local)
      return -1;
  for (std::size_t g = 0; g < grasps_.size(); ++g) {
    Grasp& gr = grasps_[g];
    if (gr.active) continue;
    gr.active = true;
    gr.hand = hand;
    gr.object = object;
    gr.hMo = hand.frames->pose(hand.local).inverse() * objects_[object]->pose(0);
    gr.force.setZero();
    gr.moment.setZero();
    gr.first_row = -1;
    return static_cast<int>(g);
  }
  return -1;
}

bool GraspRows::release(int handle) {
  if (handle < 0 || handle >= static_cast<int>(grasps_.size()) || !grasps_[handle].active) return false;
  grasps_[handle].active = false;
  grasps_[handle].first_row = -1;
  return true;
}

bool GraspRows::held(int object) const {
  for (const Grasp& g : grasps_)
    if (g.active && g.object == object) return true;
  return false;
}

int GraspRows::numGrasps() const {
  int n = 0;
  for (const Grasp& g : grasps_) n += g.active ? 1 : 0;
  return n;
}

void GraspRows::angularJacobian(const constraints::BodyFrames& frames, int local, const Vector3& x, int nv,
                                Eigen::Matrix3Xd& Jw) {
  // rigid body: J_p(x + e_j) − J_p(x) = [ω]× e_j (J_p is affine in the point)
  auto j0 = J0_.leftCols(nv);
  auto j1 = J1_.leftCols(nv);
  frames.pointJacobian(local, x, j0);
  frames.pointJacobian(local, x + Vector3::UnitY(), j1);
  Jw.row(0).head(nv) = j1.row(2) - j0.row(2);  // (ω × e_y)_z = ω_x
  frames.pointJacobian(local, x + Vector3::UnitZ(), j1);
  Jw.row(1).head(nv) = j1.row(0) - j0.row(0);  // (ω × e_z)_x = ω_y
  frames.pointJacobian(local, x + Vector3::UnitX(), j1);
  Jw.row(2).head(nv) = j1.row(1) - j0.row(1);  // (ω × e_x)_y = ω_z
}

void GraspRows::addRows(int id, double /*dt*/, constraints::RowSet& rows) {
  for (std::size_t g = 0; g < grasps_.size(); ++g) {
    Grasp& gr = grasps_[g];
    gr.first_row = -1;
    if (!gr.active) continue;
    const RigidObject& obj = *objects_[gr.object];
    const int so = systems_[gr.object], sh = gr.hand.system;
    const int nvo = obj.nv(), nvh = rows.systemNv(sh);
    if (nvh > Jp_hand_.cols()) continue;  // hand larger than the buffers: not held (max_nv too small)
    const SE3& oMo = obj.pose(0);
    const SE3 oMt = gr.hand.frames->pose(gr.hand.local) * gr.hMo;
    const Vector3 ep = oMo.p - oMt.p;
    const Vector3 er = math::logSO3(oMo.R * oMt.R.transpose());
    {
      auto jo = Jp_obj_.leftCols(nvo);
      obj.pointJacobian(0, oMo.p, jo);
      auto jh = Jp_hand_.leftCols(nvh);
      gr.hand.frames->pointJacobian(gr.hand.local, oMo.p, jh);
    }
    angularJacobian(obj, 0, oMo.p, nvo, Jw_obj_);
    angularJacobian(*gr.hand.frames, gr.hand.local, oMo.p, nvh, Jw_hand_);
    for (int i = 0; i < 6; ++i) {
      constraints::RowInfo info;
      info.kind = constraints::RowKind::kBilateral;
      info.source = constraints::RowSource::kGrasp;
      info.producer = id;
      info.tag = static_cast<int>(6 * g) + i;
      info.distance = i < 3 ? ep[i] : er[i - 3];
      info.recovery_speed = recovery_speed_;
      info.system_a = so;
      info.system_b = sh;
      const int r = rows.add(info);
      if (r < 0) continue;
      if (i == 0) gr.first_row = r;
      const Eigen::Matrix3Xd& Jo = i < 3 ? Jp_obj_ : Jw_obj_;
      const Eigen::Matrix3Xd& Jh = i < 3 ? Jp_hand_ : Jw_hand_;
      rows.jacobian(r, so) = Jo.row(i % 3).head(nvo);
      rows.jacobian(r, sh) = -Jh.row(i % 3).head(nvh);
    }
  }
}

void GraspRows::solved(int id, const constraints::RowSet& rows) {
  for (Grasp& gr : grasps_) {
    gr.force.setZero();
    gr.moment.setZero();
  }
  for (int r = 0; r < rows.size(); ++r) {
    const constraints::RowInfo& info = rows.info(r);
    if (info.producer != id || info.tag < 0) continue;
    Grasp& gr = grasps_[static_cast<std::size_t>(info.tag / 6)];
    const int i = info.tag % 6;
    if (i < 3)
      gr.force[i] = info.lambda;
    else
      gr.moment[i - 3] = info.lambda;
  }
}

Vector3 GraspRows::force(int handle) const {
  if (handle < 0 || handle >= static_cast<int>(grasps_.size())) return Vector3::Zero();
  return grasps_[handle].force;
}

Vector3 GraspRows::moment(int handle) const {
  if (handle < 0 || handle >= static_cast<int>(grasps_.size())) return Vector3::Zero();
  return grasps_[handle].moment;
}

}  // namespace mannequin::constraints
