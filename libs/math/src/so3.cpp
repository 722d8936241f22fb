#include "mannequin/math/so3.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace mannequin::math {

namespace {
constexpr double kPi = 3.14159265358979323846;
// below this angle the trigonometric coefficients are replaced by their Taylor series
constexpr double kSmallAngle = 1e-4;
}  // namespace

Matrix3 hat(const Vector3& w) {
  Matrix3 W;
  W << 0.0, -w.z(), w.y(),
       w.z(), 0.0, -w.x(),
       -w.y(), w.x(), 0.0;
  return W;
}

Vector3 vee(const Matrix3& W) {
  return 0.5 * Vector3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
}

namespace {
/// I + a[ω] + b[ω]², with [ω]² = ω ωᵀ − |ω|² I (no 3 × 3 product): Rodrigues' form of exp and of the
/// SO(3) Jacobians.
Matrix3 identityPlusHat(const Vector3& w, double a, double b) {
  const double c = 1.0 - b * w.squaredNorm();
  const double bx = b * w.x(), by = b * w.y(), bz = b * w.z();
  const double ax = a * w.x(), ay = a * w.y(), az = a * w.z();
  const double bxy = bx * w.y(), bxz = bx * w.z(), byz = by * w.z();
  Matrix3 R;
  R << c + bx * w.x(), bxy - az, bxz + ay,
       bxy + az, c + by * w.y(), byz - ax,
       bxz - ay, byz + ax, c + bz * w.z();
  return R;
}
}  // namespace

Matrix3 expSO3(const Vector3& w) {
  // Rodrigues (thesis 1.11): I + a[ω] + b[ω]², a = sinθ/θ, b = (1−cosθ)/θ²
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  double a, b;
  if (t < kSmallAngle) {
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
  } else {
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
  }
  return identityPlusHat(w, a, b);
}

Vector3 logSO3(const Matrix3& R) {
  // angle from both the trace (cos) and the antisymmetric part (sin): accurate everywhere
  const Vector3 s = vee(R);  // = sinθ u
  const double sin_t = s.norm();
  const double cos_t = 0.5 * (R.trace() - 1.0);
  const double t = std::atan2(sin_t, cos_t);
  if (t < kSmallAngle) {
    // θ/sinθ ≈ 1 + θ²/6
    return (1.0 + t * t / 6.0) * s;
  }
  if (t < kPi - 1e-2) {
    return (t / sin_t) * s;
  }
  // near π: u uᵀ = (R + Rᵀ − 2cosθ I) / (2(1 − cosθ)); take the best-conditioned column
  const Matrix3 B = (0.5 * (R + R.transpose()) - cos_t * Matrix3::Identity()) / (1.0 - cos_t);
  int k = 0;
  B.diagonal().maxCoeff(&k);
  Vector3 u = B.col(k) / std::sqrt(std::max(B(k, k), 1e-300));
  u.normalize();
  // the sign comes from the antisymmetric part (sinθ u); at exactly π pick a canonical sign
  const double d = u.dot(s);
  if (d < 0.0 || (d == 0.0 && u(k) < 0.0)) u = -u;
  return t * u;
}

namespace {
// coefficients of [ω] and [ω]² shared by the SO(3) Jacobians
void jacobianCoefficients(const Vector3& w, double* a, double* b) {
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  if (t < kSmallAngle) {
    *a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;     // (1 − cosθ)/θ²
    *b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;  // (θ − sinθ)/θ³
  } else {
    *a = (1.0 - std::cos(t)) / t2;
    *b = (t - std::sin(t)) / (t2 * t);
  }
}
double inverseCoefficient(const Vector3& w) {
  // 1/θ² − (1 + cosθ)/(2θ sinθ)
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  if (t < kSmallAngle) return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  return 1.0 / t2 - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
}
}  // namespace

Matrix3 rightJacobianSO3(const Vector3& w) {
  double a, b;
  jacobianCoefficients(w, &a, &b);
  return identityPlusHat(w, -a, b);
}

Matrix3 leftJacobianSO3(const Vector3& w) {
  double a, b;
  jacobianCoefficients(w, &a, &b);
  return identityPlusHat(w, a, b);
}

Matrix3 rightJacobianInverseSO3(const Vector3& w) {
  const Matrix3 W = hat(w);
  return Matrix3::Identity() + 0.5 * W + inverseCoefficient(w) * W * W;
}

Matrix3 leftJacobianInverseSO3(const Vector3& w) {
  const Matrix3 W = hat(w);
  return Matrix3::Identity() - 0.5 * W + inverseCoefficient(w) * W * W;
}

Matrix3 orthonormalize(const Matrix3& R) {
  if (!R.allFinite()) return Matrix3::Identity();
  Eigen::JacobiSVD<Matrix3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 D = Matrix3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

bool isRotation(const Matrix3& R, double tol) {
  if (!R.allFinite()) return false;
  return (R.transpose() * R - Matrix3::Identity()).cwiseAbs().maxCoeff() <= tol &&
         std::abs(R.determinant() - 1.0) <= tol;
}

}  // namespace mannequin::math
