#include "mannequin/scenario/trajectory.hpp"

#include <algorithm>
#include <stdexcept>

namespace mannequin::scenario {

using math::expSO3;
using math::leftJacobianInverseSO3;
using math::leftJacobianSO3;
using math::logSO3;

double minimumJerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
}

double minimumJerkDot(double tau) {
  if (tau <= 0.0 || tau >= 1.0) return 0.0;
  return tau * tau * (30.0 + tau * (-60.0 + 30.0 * tau));
}

double minimumJerkDDot(double tau) {
  if (tau <= 0.0 || tau >= 1.0) return 0.0;
  return tau * (60.0 + tau * (-180.0 + 120.0 * tau));
}

Quintic3::Quintic3(const Vector3& x0, const Vector3& v0, const Vector3& a0, const Vector3& x1, const Vector3& v1,
                   const Vector3& a1, double T)
    : T_(T) {
  if (!(T > 0.0)) throw std::invalid_argument("Quintic3: duration must be > 0");
  const Vector3 h = x1 - x0;
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  c_.col(0) = x0;
  c_.col(1) = v0;
  c_.col(2) = 0.5 * a0;
  c_.col(3) = (20.0 * h - (8.0 * v1 + 12.0 * v0) * T - (3.0 * a0 - a1) * T2) / (2.0 * T3);
  c_.col(4) = (-30.0 * h + (14.0 * v1 + 16.0 * v0) * T + (3.0 * a0 - 2.0 * a1) * T2) / (2.0 * T4);
  c_.col(5) = (12.0 * h - 6.0 * (v1 + v0) * T + (a1 - a0) * T2) / (2.0 * T5);
}

void Quintic3::sample(double t, Vector3& x, Vector3& v, Vector3& a) const {
  if (T_ <= 0.0) {
    x = c_.col(0);
    v.setZero();
    a.setZero();
    return;
  }
  const bool after = t >= T_;
  t = std::clamp(t, 0.0, T_);
  x = c_.col(0) + t * (c_.col(1) + t * (c_.col(2) + t * (c_.col(3) + t * (c_.col(4) + t * c_.col(5)))));
  if (after) {  // held at the end (its end velocity and acceleration are zero in every use here)
    v.setZero();
    a.setZero();
    return;
  }
  v = c_.col(1) + t * (2.0 * c_.col(2) + t * (3.0 * c_.col(3) + t * (4.0 * c_.col(4) + t * 5.0 * c_.col(5))));
  a = 2.0 * c_.col(2) + t * (6.0 * c_.col(3) + t * (12.0 * c_.col(4) + t * 20.0 * c_.col(5)));
}

Vector3 Quintic3::accelerationBound() const {
  const double T = T_;
  return 2.0 * c_.col(2).cwiseAbs() + 6.0 * T * c_.col(3).cwiseAbs() + 12.0 * T * T * c_.col(4).cwiseAbs() +
         20.0 * T * T * T * c_.col(5).cwiseAbs();
}

MinimumJerkTrajectory::MinimumJerkTrajectory(const Setpoint& start, const SE3& goal, double duration)
    : start_(start.pose), goal_(goal), T_(duration) {
  if (!(duration > 0.0)) throw std::invalid_argument("MinimumJerkTrajectory: duration must be > 0");
  axis_ = logSO3(start.pose.R.transpose() * goal.R);
  const Vector3 z = Vector3::Zero();
  pos_ = Quintic3(start.pose.p, start.twist.tail<3>(), z, goal.p, z, z, duration);
  rot_ = Quintic3(z, start.twist.head<3>(), z, z, z, z, duration);
}

Setpoint MinimumJerkTrajectory::sample(double t) const {
  Setpoint out;
  Vector3 p, v, a;
  pos_.sample(t, p, v, a);
  const double tau = std::clamp(t / T_, 0.0, 1.0);
  const Matrix3 R_nom = start_.R * expSO3(minimumJerk(tau) * axis_);
  const Vector3 w_nom = R_nom * axis_ * (minimumJerkDot(tau) / T_);
  Vector3 r, rd, rdd;
  rot_.sample(t, r, rd, rdd);
  const Matrix3 E = expSO3(r);
  out.pose = SE3(E * R_nom, p);
  out.twist.head<3>() = leftJacobianSO3(r) * rd + E * w_nom;
  out.twist.tail<3>() = v;
  return out;
}

Blend::Blend(const Setpoint& from, const Setpoint& to, double duration) : T_(duration) {
  if (!(duration > 0.0)) throw std::invalid_argument("Blend: duration must be > 0");
  const Vector3 z = Vector3::Zero();
  e_ = Quintic3(from.pose.p - to.pose.p, from.twist.tail<3>() - to.twist.tail<3>(), z, z, z, z, duration);
  const Vector3 r0 = logSO3(from.pose.R * to.pose.R.transpose());
  const Vector3 rd0 = leftJacobianInverseSO3(r0) * (from.twist.head<3>() - expSO3(r0) * to.twist.head<3>());
  r_ = Quintic3(r0, rd0, z, z, z, z, duration);
}

Setpoint Blend::apply(double t, const Setpoint& target) const {
  if (t >= T_) return target;
  Setpoint out;
  Vector3 e, ed, edd, r, rd, rdd;
  e_.sample(t, e, ed, edd);
  r_.sample(t, r, rd, rdd);
  const Matrix3 E = expSO3(r);
  out.pose = SE3(E * target.pose.R, target.pose.p + e);
  out.twist.head<3>() = leftJacobianSO3(r) * rd + E * target.twist.head<3>();
  out.twist.tail<3>() = target.twist.tail<3>() + ed;
  return out;
}

}  // namespace mannequin::scenario
