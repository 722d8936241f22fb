#include "mannequin/constraints/swing_twist.hpp"

#include <cmath>

#include "mannequin/math/so3.hpp"

namespace mannequin::constraints {

using Eigen::Matrix3d;
using Eigen::RowVector3d;
using Eigen::Vector3d;

SwingTwist swingTwist(const Matrix3d& R, const Vector3d& t, const Vector3d& fallback, bool jacobians) {
  SwingTwist st;
  const Vector3d z1 = R * t;
  const Vector3d w = t.cross(z1);
  const double sin_t = w.norm(), cos_t = t.dot(z1);
  const double th = std::atan2(sin_t, cos_t);
  st.swing_angle = th;
  if (sin_t > 1e-12) {
    st.swing_dir = w / sin_t;
  } else if (cos_t < 0) {
    // θ_s = π: t × z1 vanishes; the swing axis is any axis ⟂ t: take the fallback's part ⟂ t
    const Vector3d f = fallback - fallback.dot(t) * t;
    st.swing_dir = f.norm() > 1e-9 ? Vector3d(f.normalized()) : Vector3d(t.unitOrthogonal());
  } else {
    st.swing_dir = fallback;  // θ_s = 0: s = 0, u is not used
  }
  // g = θ/sin θ and f = (sin θ − θ cos θ)/sin³ θ, by series near 0
  double g, f;
  if (th < 1e-3) {
    g = 1.0 + th * th / 6.0;
    f = 1.0 / 3.0 + 2.0 * th * th / 15.0;
  } else {
    g = th / sin_t;
    f = (sin_t - th * cos_t) / (sin_t * sin_t * sin_t);
  }
  st.swing = sin_t > 1e-12 || th < 1e-3 ? Vector3d(g * w) : Vector3d(th * st.swing_dir);
  // the twist: R_t = R_sᵀ R, signed angle about t. R_sᵀ is the geodesic rotation taking z1 back to t:
  // without trigonometry, I + [v] + [v]²/(1 + c) with v = z1 × t = −w, c = t·z1 (Rodrigues with
  // sin θ_s = |v|, 1 − cos θ_s = 1 − c); near θ_s = π (1 + c → 0) from exp(−[s]) instead
  Matrix3d Rt;
  if (cos_t > -0.5) {
    const Matrix3d V = math::hat(-w);
    Rt = (Matrix3d::Identity() + V + (V * V) / (1.0 + cos_t)) * R;
  } else {
    Rt = math::expSO3(st.swing).transpose() * R;
  }
  st.twist = std::atan2(t.dot(math::vee(Rt)), 0.5 * (Rt.trace() - 1.0));
  st.singular = th > kSwingSingular;
  if (!jacobians) return st;
  // dθ_s/dω = (t × Rᵀ e_θ)ᵀ, e_θ the direction in which z1 moves when θ_s grows
  const Vector3d e_th = -sin_t * t + cos_t * st.swing_dir.cross(t);  // sin θ_s = |t × z1|, cos θ_s = t·z1
  st.swing_angle_jacobian = t.cross(R.transpose() * e_th).transpose();
  if (st.singular) return st;
  const Matrix3d T = math::hat(t);
  st.swing_jacobian = T * (f * z1 * t.transpose() - g * Matrix3d::Identity()) * R * T;  // (61)
  st.twist_jacobian = t.transpose() - t.transpose() * math::rightJacobianSO3(st.swing) * st.swing_jacobian;
  return st;
}

Matrix3d swingRotation(const SwingTwist& st) { return math::expSO3(st.swing); }

Matrix3d twistRotation(const SwingTwist& st, const Vector3d& t) { return math::expSO3(st.twist * t); }

double ellipseLevel(const skeleton::BallLimit& l, const Vector3d& s) {
  const double x = (s.dot(l.swing_x) - l.swing_cx) / l.swing_a, y = (s.dot(l.swing_y) - l.swing_cy) / l.swing_b;
  return x * x + y * y;
}

RowVector3d ellipseGradient(const skeleton::BallLimit& l, const Vector3d& s) {
  const double a2 = l.swing_a * l.swing_a, b2 = l.swing_b * l.swing_b;
  return (2.0 * (s.dot(l.swing_x) - l.swing_cx) / a2 * l.swing_x + 2.0 * (s.dot(l.swing_y) - l.swing_cy) / b2 * l.swing_y)
      .transpose();
}

double ellipseRadius(const skeleton::BallLimit& l, const Vector3d& u) {
  // ρ > 0 with h(ρu) = 1: ρ² uᵀQu − 2ρ uᵀQc + cᵀQc − 1 = 0 (cᵀQc < 1: one positive root)
  const double ux = u.dot(l.swing_x) / l.swing_a, uy = u.dot(l.swing_y) / l.swing_b;
  const double cx = l.swing_cx / l.swing_a, cy = l.swing_cy / l.swing_b;
  const double A = ux * ux + uy * uy, B = ux * cx + uy * cy, C = cx * cx + cy * cy - 1.0;
  if (A <= 0) return l.swing_a;  // u ∥ t: not a swing direction
  return (B + std::sqrt(std::max(0.0, B * B - A * C))) / A;
}

BallLimitDistances ballLimitDistances(const skeleton::BallLimit& l, const Matrix3d& R, bool jacobians) {
  BallLimitDistances d;
  d.st = swingTwist(R, l.twist_axis, l.swing_x, jacobians);
  const SwingTwist& st = d.st;
  const double rho = ellipseRadius(l, st.swing_dir);
  d.swing_excess = std::max(0.0, st.swing_angle - rho);
  if (st.singular) {
    d.singular = true;
    d.swing = rho - st.swing_angle;
    if (jacobians) d.swing_jacobian = -st.swing_angle_jacobian;
    return d;
  }
  // κ = 1/(dh/dρ along u at the boundary) = 1/(2 uᵀQ(ρu − c))
  const Vector3d& u = st.swing_dir;
  const double slope = ellipseGradient(l, rho * u).dot(u);
  d.swing_scale = slope > 1e-12 ? 1.0 / slope : 0.5 * std::min(l.swing_a, l.swing_b);
  d.swing = d.swing_scale * (1.0 - ellipseLevel(l, st.swing));
  d.twist_lower = st.twist - l.twist_lower;
  d.twist_upper = l.twist_upper - st.twist;
  if (!jacobians) return d;
  d.swing_jacobian = -d.swing_scale * ellipseGradient(l, st.swing) * st.swing_jacobian;
  d.twist_jacobian = st.twist_jacobian;
  return d;
}

}  // namespace mannequin::constraints
