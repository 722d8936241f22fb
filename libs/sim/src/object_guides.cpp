#include "mannequin/sim/object_guides.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "mannequin/math/so3.hpp"

namespace mannequin::sim {

using control::MechanismType;
using math::Matrix3;
using math::SE3;
using math::Vector3;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kRowsPerGuide = 16;  // tags: 0–2 locked position axes, 3–5 rotation, 6–7 tilts, 8–15 stops
constexpr int kRotation = 3, kTilt = 6, kStops = 8;

Matrix3 hat(const Vector3& v) {
  Matrix3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Coordinate c of a type: which base axis it measures a position along (0, 1, 2), or −1 for θ.
int coordinateAxis(MechanismType type, int c) {
  switch (type) {
    case MechanismType::kPrismatic: return 2;
    case MechanismType::kSlidingPivot: return c == 0 ? 2 : -1;
    case MechanismType::kPlane: return c == 0 ? 0 : c == 1 ? 1 : c == 2 ? -1 : 2;
    case MechanismType::kCurve: break;
  }
  return 2;
}

}  // namespace

struct GuideRows::Geometry {
  Vector3 r;        // relative position, base axes
  Matrix3 R;        // relative rotation R_bᵀ R_o
  Vector3 tilt;     // z_b × z_o (world)
  Vector3 rot_err;  // log(R_o R_bᵀ) (world)
  double theta = 0.0;
};

GuideRows::GuideRows(std::vector<const constraints::RigidObject*> objects, std::vector<int> object_systems, double activation,
                     double recovery_speed)
    : objects_(std::move(objects)), systems_(std::move(object_systems)), activation_(activation), recovery_speed_(recovery_speed) {
  if (objects_.size() != systems_.size()) throw std::invalid_argument("GuideRows: objects and object_systems differ in size");
  for (std::size_t i = 0; i < objects_.size(); ++i)
    if (!objects_[i] || systems_[i] < 0) throw std::invalid_argument("GuideRows: null object or negative system");
  if (!(activation > 0.0) || !std::isfinite(activation) || !(recovery_speed > 0.0) || !std::isfinite(recovery_speed))
    throw std::invalid_argument("GuideRows: activation and recovery_speed must be finite and > 0");
  guides_.resize(objects_.size());
  Jp_.setZero(3, 6);
  Jw_.setZero(3, 6);
  J1_.setZero(3, 6);
}

bool GuideRows::supports(const control::MechanismSpec& spec, std::string* why) {
  const auto no = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (spec.type == MechanismType::kCurve) return no("a curve cannot guide an object (prismatic, sliding_pivot or plane)");
  for (int i = 0; i < spec.force.size(); ++i)
    if (spec.force(i) != 0.0) return no("an object's guide takes no coordinate forces ('force', 'normal_force')");
  if (!spec.base.R.allFinite() || !spec.base.p.allFinite()) return no("the mechanism's origin is not finite");
  if ((spec.base.R.transpose() * spec.base.R - Matrix3::Identity()).norm() > 1e-6)
    return no("the mechanism's origin rotation is not a rotation");
  const int d = control::mechanismDimension(spec.type);
  if ((spec.lower.size() != 0 && spec.lower.size() != d) || spec.lower.size() != spec.upper.size())
    return no("expected " + std::to_string(d) + " pairs of stops for a " + control::toString(spec.type));
  for (int i = 0; i < spec.lower.size(); ++i)
    if (std::isnan(spec.lower(i)) || std::isnan(spec.upper(i)) || spec.lower(i) > spec.upper(i))
      return no("stop " + std::to_string(i) + ": lower > upper or NaN");
  return true;
}

void GuideRows::attach(int object, const control::MechanismSpec& spec) {
  if (object < 0 || object >= static_cast<int>(objects_.size()))
    throw std::invalid_argument("GuideRows::attach: no object " + std::to_string(object));
  const constraints::RigidObject& o = *objects_[static_cast<std::size_t>(object)];
  if (o.hinged()) throw std::invalid_argument("guide on '" + o.name() + "': a hinged object is guided by its hinge already");
  std::string why;
  if (!supports(spec, &why)) throw std::invalid_argument("guide on '" + o.name() + "': " + why);
  Guide& g = guides_[static_cast<std::size_t>(object)];
  g.spec = spec;
  const int d = control::mechanismDimension(spec.type);
  g.lower.setConstant(-kInf);
  g.upper.setConstant(kInf);
  if (spec.lower.size() == d) {
    g.lower.head(d) = spec.lower;
    g.upper.head(d) = spec.upper;
  } else if (spec.type == MechanismType::kPlane) {
    g.lower(3) = g.upper(3) = 0.0;  // n locked on the plane by default (virtual_mechanism.hpp)
  }
  g.force.setZero();
  g.active = true;
}

bool GuideRows::detach(int object) {
  if (object < 0 || object >= static_cast<int>(guides_.size()) || !guides_[static_cast<std::size_t>(object)].active) return false;
  guides_[static_cast<std::size_t>(object)].active = false;
  guides_[static_cast<std::size_t>(object)].force.setZero();
  return true;
}

bool GuideRows::guided(int object) const {
  return object >= 0 && object < static_cast<int>(guides_.size()) && guides_[static_cast<std::size_t>(object)].active;
}

GuideRows::Geometry GuideRows::measure(int object) const {
  const Guide& g = guides_[static_cast<std::size_t>(object)];
  const SE3& oMo = objects_[static_cast<std::size_t>(object)]->pose(0);
  const SE3& oMb = g.spec.base;
  Geometry m;
  m.r = oMb.R.transpose() * (oMo.p - oMb.p);
  m.R = oMb.R.transpose() * oMo.R;
  m.tilt = oMb.R.col(2).cross(oMo.R.col(2));
  m.rot_err = math::logSO3(oMo.R * oMb.R.transpose());
  m.theta = std::atan2(m.R(1, 0), m.R(0, 0));
  return m;
}

control::MechVector GuideRows::coordinates(int object) const {
  if (!guided(object)) return control::MechVector::Zero(1);
  const Guide& g = guides_[static_cast<std::size_t>(object)];
  const Geometry m = measure(object);
  const int d = control::mechanismDimension(g.spec.type);
  control::MechVector s(d);
  for (int c = 0; c < d; ++c) {
    const int axis = coordinateAxis(g.spec.type, c);
    s(c) = axis < 0 ? m.theta : m.r(axis);
  }
  return s;
}

double GuideRows::positionError(int object) const {
  if (!guided(object)) return 0.0;
  const Guide& g = guides_[static_cast<std::size_t>(object)];
  const Geometry m = measure(object);
  double e = 0.0;
  if (g.spec.type != MechanismType::kPlane) e = std::max(std::abs(m.r.x()), std::abs(m.r.y()));
  const int d = control::mechanismDimension(g.spec.type);
  for (int c = 0; c < d; ++c) {  // position coordinates outside their stops
    const int axis = coordinateAxis(g.spec.type, c);
    if (axis < 0) continue;
    e = std::max({e, g.lower(c) - m.r(axis), m.r(axis) - g.upper(c)});
  }
  return e;
}

double GuideRows::angleError(int object) const {
  if (!guided(object)) return 0.0;
  const Guide& g = guides_[static_cast<std::size_t>(object)];
  const Geometry m = measure(object);
  if (g.spec.type == MechanismType::kPrismatic) return m.rot_err.norm();
  return std::atan2(m.tilt.norm(), g.spec.base.R.col(2).dot(objects_[static_cast<std::size_t>(object)]->pose(0).R.col(2)));
}

math::Vector3 GuideRows::force(int object) const {
  return guided(object) ? guides_[static_cast<std::size_t>(object)].force : Vector3::Zero();
}

void GuideRows::addRows(int id, double /*dt*/, constraints::RowSet& rows) {
  for (std::size_t k = 0; k < guides_.size(); ++k) {
    const Guide& g = guides_[k];
    if (!g.active) continue;
    const constraints::RigidObject& obj = *objects_[k];
    const int sys = systems_[k], nv = obj.nv();
    const Geometry m = measure(static_cast<int>(k));
    const SE3& oMb = g.spec.base;
    const Vector3 po = obj.pose(0).p;
    {
      auto jp = Jp_.leftCols(nv);
      obj.pointJacobian(0, po, jp);
      // J_ω from point Jacobians: J_p(x + e_j) − J_p(x) = [ω]× e_j for a rigid body
      auto j1 = J1_.leftCols(nv);
      obj.pointJacobian(0, po + Vector3::UnitY(), j1);
      Jw_.row(0).head(nv) = j1.row(2) - jp.row(2);
      obj.pointJacobian(0, po + Vector3::UnitZ(), j1);
      Jw_.row(1).head(nv) = j1.row(0) - jp.row(0);
      obj.pointJacobian(0, po + Vector3::UnitX(), j1);
      Jw_.row(2).head(nv) = j1.row(1) - jp.row(1);
    }
    const auto add = [&](int tag, constraints::RowKind kind, double d) {
      constraints::RowInfo info;
      info.kind = kind;
      info.source = constraints::RowSource::kGuide;
      info.producer = id;
      info.tag = static_cast<int>(k) * kRowsPerGuide + tag;
      info.distance = d;
      info.recovery_speed = recovery_speed_;
      info.system_a = sys;
      return rows.add(info);
    };
    const MechanismType type = g.spec.type;
    // locked position axes (prismatic, sliding pivot): the object's origin on the base's z axis
    if (type != MechanismType::kPlane)
      for (int i = 0; i < 2; ++i) {
        const int r = add(i, constraints::RowKind::kBilateral, m.r(i));
        if (r >= 0) rows.jacobian(r, sys).noalias() = oMb.R.col(i).transpose() * Jp_.leftCols(nv);
      }
    if (type == MechanismType::kPrismatic) {
      // R_o = R_b: e = log(R_o R_bᵀ), ė = J_l⁻¹(e) ω (world ω: a left perturbation)
      const Matrix3 Jli = math::leftJacobianInverseSO3(m.rot_err);
      for (int i = 0; i < 3; ++i) {
        const int r = add(kRotation + i, constraints::RowKind::kBilateral, m.rot_err(i));
        if (r >= 0) rows.jacobian(r, sys).noalias() = Jli.row(i) * Jw_.leftCols(nv);
      }
    } else {
      const Matrix3 A = -hat(oMb.R.col(2)) * hat(obj.pose(0).R.col(2));  // ∂(z_b × z_o)/∂ω
      for (int i = 0; i < 2; ++i) {  // z_o = z_b: the tilts about the base's x and y axes
        const int r = add(kTilt + i, constraints::RowKind::kBilateral, oMb.R.col(i).dot(m.tilt));
        if (r >= 0) rows.jacobian(r, sys).noalias() = (oMb.R.col(i).transpose() * A) * Jw_.leftCols(nv);
      }
    }
    // the coordinates' stops
    const int d = control::mechanismDimension(type);
    for (int c = 0; c < d; ++c) {
      const double lo = g.lower(c), hi = g.upper(c);
      if (!std::isfinite(lo) && !std::isfinite(hi)) continue;
      const int axis = coordinateAxis(type, c);
      const double s = axis < 0 ? m.theta : m.r(axis);
      const Vector3 dir = oMb.R.col(axis < 0 ? 2 : axis);
      const auto rate = [&](int r, double sign) {
        if (r < 0) return;
        if (axis < 0)
          rows.jacobian(r, sys).noalias() = sign * (dir.transpose() * Jw_.leftCols(nv));
        else
          rows.jacobian(r, sys).noalias() = sign * (dir.transpose() * Jp_.leftCols(nv));
      };
      if (lo == hi) {
        rate(add(kStops + 2 * c, constraints::RowKind::kBilateral, s - lo), 1.0);
        continue;
      }
      if (std::isfinite(lo) && s - lo <= activation_) rate(add(kStops + 2 * c, constraints::RowKind::kUnilateral, s - lo), 1.0);
      if (std::isfinite(hi) && hi - s <= activation_) rate(add(kStops + 2 * c + 1, constraints::RowKind::kUnilateral, hi - s), -1.0);
    }
  }
}

void GuideRows::solved(int id, const constraints::RowSet& rows) {
  for (Guide& g : guides_) g.force.setZero();
  for (int r = 0; r < rows.size(); ++r) {
    const constraints::RowInfo& info = rows.info(r);
    if (info.producer != id || info.tag < 0) continue;
    const std::size_t k = static_cast<std::size_t>(info.tag / kRowsPerGuide);
    const int tag = info.tag % kRowsPerGuide;
    Guide& g = guides_[k];
    // the position rows' forces: λ along the row's world direction
    int axis = -1;
    if (tag < kRotation)
      axis = tag;
    else if (tag >= kStops)
      axis = coordinateAxis(g.spec.type, (tag - kStops) / 2);
    if (axis < 0) continue;
    const double sign = tag >= kStops && (tag - kStops) % 2 == 1 ? -1.0 : 1.0;
    g.force += sign * info.lambda * g.spec.base.R.col(axis);
  }
}

}  // namespace mannequin::sim
