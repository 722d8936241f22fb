#include "mannequin/control/virtual_mechanism.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mannequin::control {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

Matrix3 rotZ(double a) {
  Matrix3 R;
  const double c = std::cos(a), s = std::sin(a);
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}

// twist angle about z of a rotation (swing-twist decomposition)
double twistAboutZ(const Matrix3& R) {
  const Eigen::Quaterniond q(R);
  return 2.0 * std::atan2(q.z(), q.w());
}

double wrapToPi(double a) { return std::remainder(a, 2.0 * M_PI); }

void bad(const std::string& msg) { throw std::invalid_argument("virtual mechanism: " + msg); }
}  // namespace

const char* toString(MechanismType type) {
  switch (type) {
    case MechanismType::kPrismatic: return "prismatic";
    case MechanismType::kSlidingPivot: return "sliding_pivot";
    case MechanismType::kPlane: return "plane";
    case MechanismType::kCurve: return "curve";
  }
  return "?";
}

MechanismType mechanismTypeFromString(const std::string& name) {
  for (MechanismType t : {MechanismType::kPrismatic, MechanismType::kSlidingPivot, MechanismType::kPlane,
                          MechanismType::kCurve})
    if (name == toString(t)) return t;
  throw std::invalid_argument("unknown mechanism type '" + name + "' (prismatic, sliding_pivot, plane, curve)");
}

int mechanismDimension(MechanismType type) {
  switch (type) {
    case MechanismType::kPrismatic: return 1;
    case MechanismType::kSlidingPivot: return 2;
    case MechanismType::kPlane: return 4;
    case MechanismType::kCurve: return 1;
  }
  return 1;
}

VirtualMechanism::VirtualMechanism(MechanismSpec spec) : spec_(std::move(spec)) {
  dim_ = mechanismDimension(spec_.type);
  if (!spec_.base.allFinite() || !math::isRotation(spec_.base.R, 1e-6)) bad("base pose is not a finite rigid transform");
  if (!std::isfinite(spec_.friction) || spec_.friction <= 0) bad("friction must be > 0");
  if (spec_.type == MechanismType::kCurve) {
    if (spec_.points.size() < 2) bad("a curve needs at least 2 points");
    for (size_t i = 0; i < spec_.points.size(); ++i) {
      if (!spec_.points[i].allFinite()) bad("curve point " + std::to_string(i) + " is not finite");
      if (i > 0 && (spec_.points[i] - spec_.points[i - 1]).norm() < 1e-9)
        bad("curve points " + std::to_string(i - 1) + " and " + std::to_string(i) + " coincide");
    }
  }
  // force
  force_ = MechVector::Zero(dim_);
  if (spec_.force.size() != 0) {
    if (spec_.force.size() != dim_) bad("force has " + std::to_string(spec_.force.size()) + " values, expected " + std::to_string(dim_));
    if (!spec_.force.allFinite()) bad("force is not finite");
    force_ = spec_.force;
  }
  // stops (defaults, then the spec's)
  lower_ = MechVector::Constant(dim_, -kInf);
  upper_ = MechVector::Constant(dim_, kInf);
  if (spec_.type == MechanismType::kPlane && force_(3) == 0.0) lower_(3) = upper_(3) = 0.0;
  if (spec_.type == MechanismType::kCurve) {
    lower_(0) = 0.0;
    upper_(0) = static_cast<double>(spec_.points.size() - 1);
  }
  if (spec_.lower.size() != 0 || spec_.upper.size() != 0) {
    if (spec_.lower.size() != dim_ || spec_.upper.size() != dim_)
      bad(std::string("limits of a ") + toString(spec_.type) + " need " + std::to_string(dim_) + " values each");
    for (int i = 0; i < dim_; ++i) {
      if (std::isnan(spec_.lower(i)) || std::isnan(spec_.upper(i)) || spec_.lower(i) > spec_.upper(i))
        bad("limit " + std::to_string(i) + " has lower > upper or NaN");
      lower_(i) = std::max(lower_(i), spec_.lower(i));
      upper_(i) = std::min(upper_(i), spec_.upper(i));
    }
  }
  s_ = MechVector::Zero(dim_);
  for (int i = 0; i < dim_; ++i) s_(i) = std::clamp(0.0, lower_(i), upper_(i));
  sdot_ = MechVector::Zero(dim_);
}

void VirtualMechanism::setCoordinates(const MechVector& s) {
  if (s.size() != dim_ || !s.allFinite()) bad("coordinates of the wrong size or not finite");
  for (int i = 0; i < dim_; ++i) s_(i) = std::clamp(s(i), lower_(i), upper_(i));
  sdot_.setZero(dim_);
}

void VirtualMechanism::setForce(const VectorX& f) {
  if (f.size() != dim_ || !f.allFinite()) bad("force of the wrong size or not finite");
  force_ = f;
}

void VirtualMechanism::curveAt(double u, Vector3& c, Vector3& dc) const {
  const auto& P = spec_.points;
  const int n = static_cast<int>(P.size());
  u = std::clamp(u, 0.0, static_cast<double>(n - 1));
  const int i = std::min(static_cast<int>(std::floor(u)), n - 2);
  const double t = u - i;
  if (!spec_.spline) {
    dc = P[i + 1] - P[i];
    c = P[i] + t * dc;
    return;
  }
  // Catmull–Rom tangents (one-sided at the ends), cubic Hermite segment: C¹ through the points
  const auto tangent = [&](int k) -> Vector3 {
    if (k == 0) return P[1] - P[0];
    if (k == n - 1) return P[n - 1] - P[n - 2];
    return 0.5 * (P[k + 1] - P[k - 1]);
  };
  const Vector3 m0 = tangent(i), m1 = tangent(i + 1);
  const double t2 = t * t, t3 = t2 * t;
  c = (2 * t3 - 3 * t2 + 1) * P[i] + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * P[i + 1] + (t3 - t2) * m1;
  dc = (6 * t2 - 6 * t) * P[i] + (3 * t2 - 4 * t + 1) * m0 + (-6 * t2 + 6 * t) * P[i + 1] + (3 * t2 - 2 * t) * m1;
}

SE3 VirtualMechanism::poseAt(const MechVector& s) const {
  const SE3& B = spec_.base;
  switch (spec_.type) {
    case MechanismType::kPrismatic:
      return B * SE3(Matrix3::Identity(), Vector3(0, 0, s(0)));
    case MechanismType::kSlidingPivot:
      return B * SE3(rotZ(s(1)), Vector3(0, 0, s(0)));
    case MechanismType::kPlane:
      return B * SE3(rotZ(s(2)), Vector3(s(0), s(1), s(3)));
    case MechanismType::kCurve: {
      Vector3 c, dc;
      curveAt(s(0), c, dc);
      return SE3(B.R, c);
    }
  }
  return B;
}

void VirtualMechanism::jacobian(const MechVector& s, MechJacobian& J) const {
  J.setZero(6, dim_);
  switch (spec_.type) {
    case MechanismType::kPrismatic:
      J(5, 0) = 1.0;  // v = z ṫ
      break;
    case MechanismType::kSlidingPivot:
      J(5, 0) = 1.0;  // v = z ṫ (Rz leaves z unchanged)
      J(2, 1) = 1.0;  // ω = z θ̇
      break;
    case MechanismType::kPlane: {
      const Matrix3 Rt = rotZ(s(2)).transpose();
      J.block<3, 1>(3, 0) = Rt.col(0);  // v = Rz(θ)ᵀ (ẋ, ẏ, ṅ)
      J.block<3, 1>(3, 1) = Rt.col(1);
      J(2, 2) = 1.0;                    // ω = z θ̇
      J.block<3, 1>(3, 3) = Rt.col(2);
      break;
    }
    case MechanismType::kCurve: {
      Vector3 c, dc;
      curveAt(s(0), c, dc);
      J.block<3, 1>(3, 0) = spec_.base.R.transpose() * dc;  // v = R_bᵀ c'(u) u̇
      break;
    }
  }
}

Vector6 VirtualMechanism::twist() const {
  MechJacobian J;
  jacobian(s_, J);
  return J * sdot_;
}

MechVector VirtualMechanism::project(const SE3& oMc) const {
  MechVector s = MechVector::Zero(dim_);
  const SE3 local = spec_.base.inverse() * oMc;
  switch (spec_.type) {
    case MechanismType::kPrismatic:
      s(0) = local.p.z();
      break;
    case MechanismType::kSlidingPivot:
      s(0) = local.p.z();
      s(1) = wrapToPi(twistAboutZ(local.R));
      break;
    case MechanismType::kPlane:
      s << local.p.x(), local.p.y(), wrapToPi(twistAboutZ(local.R)), local.p.z();
      break;
    case MechanismType::kCurve: {
      // closest point: coarse sampling of every segment, then Gauss–Newton on ½‖c(u) − p‖²
      const int n = static_cast<int>(spec_.points.size());
      double best_u = 0, best_d = kInf;
      Vector3 c, dc;
      for (int i = 0; i < n - 1; ++i)
        for (int k = 0; k <= 16; ++k) {
          const double u = i + k / 16.0;
          curveAt(u, c, dc);
          const double d = (c - oMc.p).squaredNorm();
          if (d < best_d) {
            best_d = d;
            best_u = u;
          }
        }
      for (int it = 0; it < 8; ++it) {
        curveAt(best_u, c, dc);
        const double g = dc.dot(c - oMc.p), h = dc.squaredNorm();
        if (h <= 0) break;
        best_u = std::clamp(best_u - g / h, 0.0, static_cast<double>(n - 1));
      }
      s(0) = best_u;
      break;
    }
  }
  for (int i = 0; i < dim_; ++i) s(i) = std::clamp(s(i), lower_(i), upper_(i));
  return s;
}

void VirtualMechanism::step(const SE3& oMc, const Vector6& V_c, const Vector6& K, const Vector6& B, double dt) {
  using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxMechanismDim, kMaxMechanismDim>;
  const SE3 oMe = pose();
  const SE3 eMc = oMe.inverse() * oMc;
  // spring toward the control frame and damper on the relative twist, effector axes
  const Vector6 e = couplingError(oMe, oMc);
  const Vector6 Vc_e = math::actTwist(eMc, V_c);
  MechJacobian J;
  jacobian(s_, J);
  SmallMatrix A = J.transpose() * B.asDiagonal() * J;
  A.diagonal().array() += spec_.friction;
  const Vector6 W = K.cwiseProduct(e) + B.cwiseProduct(Vc_e);
  const MechVector rhs = J.transpose() * W + force_;
  sdot_ = A.ldlt().solve(rhs);
  // explicit Euler, then the end stops: a clamped coordinate stops
  for (int i = 0; i < dim_; ++i) {
    const double next = s_(i) + sdot_(i) * dt;
    if (next > upper_(i) || next < lower_(i)) {
      s_(i) = std::clamp(next, lower_(i), upper_(i));
      sdot_(i) = 0.0;
    } else {
      s_(i) = next;
    }
  }
}

}  // namespace mannequin::control
