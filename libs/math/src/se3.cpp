#include "mannequin/math/se3.hpp"

namespace mannequin::math {

SE3 SE3::fromMatrix(const Matrix4& H) { return SE3(H.topLeftCorner<3, 3>(), H.topRightCorner<3, 1>()); }

Matrix4 SE3::toMatrix() const {
  Matrix4 H = Matrix4::Identity();
  H.topLeftCorner<3, 3>() = R;
  H.topRightCorner<3, 1>() = p;
  return H;
}

bool SE3::isApprox(const SE3& other, double tol) const {
  return (R - other.R).cwiseAbs().maxCoeff() <= tol && (p - other.p).cwiseAbs().maxCoeff() <= tol;
}

Matrix4 hat6(const Vector6& V) {
  Matrix4 M = Matrix4::Zero();
  M.topLeftCorner<3, 3>() = hat(V.head<3>());
  M.topRightCorner<3, 1>() = V.tail<3>();
  return M;
}

Vector6 vee6(const Matrix4& M) {
  Vector6 V;
  V << vee(M.topLeftCorner<3, 3>()), M.topRightCorner<3, 1>();
  return V;
}

SE3 expSE3(const Vector6& V) {
  // thesis 1.10 written with the left Jacobian: p = Jl(ω) v, which also covers ω = 0 exactly
  const Vector3 w = V.head<3>();
  return SE3(expSO3(w), leftJacobianSO3(w) * V.tail<3>());
}

Vector6 logSE3(const SE3& H) {
  const Vector3 w = logSO3(H.R);
  Vector6 V;
  V << w, leftJacobianInverseSO3(w) * H.p;
  return V;
}

Matrix6 Ad(const SE3& H) {
  Matrix6 A;
  A << H.R, Matrix3::Zero(), hat(H.p) * H.R, H.R;
  return A;
}

Matrix6 AdInv(const SE3& H) {
  const Matrix3 Rt = H.R.transpose();
  Matrix6 A;
  A << Rt, Matrix3::Zero(), -Rt * hat(H.p), Rt;
  return A;
}

Vector6 actTwist(const SE3& H, const Vector6& V) {
  Vector6 out;
  out.head<3>() = H.R * V.head<3>();
  out.tail<3>() = H.p.cross(out.head<3>()) + H.R * V.tail<3>();
  return out;
}

Matrix6 coAd(const SE3& H) {
  Matrix6 A;
  A << H.R, hat(H.p) * H.R, Matrix3::Zero(), H.R;
  return A;
}

Matrix6 ad(const Vector6& V) {
  Matrix6 A;
  A << hat(V.head<3>()), Matrix3::Zero(), hat(V.tail<3>()), hat(V.head<3>());
  return A;
}

SE3 interpolate(const SE3& H0, const SE3& H1, double gamma) {
  const Vector3 dw = logSO3(H0.R.transpose() * H1.R);
  return SE3(H0.R * expSO3(gamma * dw), (1.0 - gamma) * H0.p + gamma * H1.p);
}

SE3 interpolateSE3(const SE3& H0, const SE3& H1, double gamma) {
  return H0 * expSE3(gamma * logSE3(H0.inverse() * H1));
}

}  // namespace mannequin::math
