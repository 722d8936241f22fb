#include "mannequin/constraints/balance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mannequin::constraints {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Distance of u to the segment [a, b].
double segmentDistance(const Eigen::Vector2d& u, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((u - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (u - (a + t * ab)).norm();
}

bool lexLess(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

void checkOptions(const BalanceOptions& o) {
  if (o.max_points < 1) throw std::invalid_argument("balance: max_points must be >= 1");
  if (!std::isfinite(o.min_radius) || o.min_radius <= 0)
    throw std::invalid_argument("balance: min_radius must be finite and > 0 (m)");
  if (!std::isfinite(o.recovery_speed) || o.recovery_speed < 0)
    throw std::invalid_argument("balance: recovery_speed must be finite and >= 0 (m/s)");
}
}  // namespace

//---- SupportRegion ---------------------------------------------------------------------------

SupportRegion::SupportRegion(const BalanceOptions& options) : options_(options) {
  checkOptions(options);
  pts_.resize(static_cast<std::size_t>(options.max_points));
  stack_.resize(2 * static_cast<std::size_t>(options.max_points) + 1);
  setFloor(Vector3::Zero(), Vector3::UnitZ());
}

void SupportRegion::setFloor(const Vector3& point, const Vector3& normal) {
  if (!point.allFinite() || !normal.allFinite() || normal.norm() < 1e-12)
    throw std::invalid_argument("balance: the floor needs a finite point and a finite non-zero normal");
  origin_ = point;
  normal_ = normal.normalized();
  // e1: the world x axis (or y when n is along x) made orthogonal to n; e2 = n × e1 (e1, e2, n right-handed)
  Vector3 a = std::abs(normal_.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY();
  const Vector3 e1 = (a - a.dot(normal_) * normal_).normalized();
  E_.col(0) = e1;
  E_.col(1) = normal_.cross(e1);
  hull_size_ = 0;  // the points must be given again on the new floor
}

bool SupportRegion::setSupport(const std::vector<Vector3>& points) {
  hull_size_ = 0;
  area_ = 0;
  const int n = static_cast<int>(points.size());
  if (n == 0) return true;
  if (n > options_.max_points) return false;
  for (int i = 0; i < n; ++i) {
    if (!points[static_cast<std::size_t>(i)].allFinite()) return false;
    pts_[static_cast<std::size_t>(i)] = project(points[static_cast<std::size_t>(i)]);
  }
  // Andrew's monotone chain (in place: std::sort does not allocate); collinear points are dropped
  std::sort(pts_.begin(), pts_.begin() + n, lexLess);
  constexpr double kEps = 1e-12;
  int k = 0;
  for (int i = 0; i < n; ++i) {  // lower hull
    const Eigen::Vector2d& p = pts_[static_cast<std::size_t>(i)];
    while (k >= 2 && cross2(stack_[k - 1] - stack_[k - 2], p - stack_[k - 2]) <= kEps) --k;
    stack_[static_cast<std::size_t>(k++)] = p;
  }
  for (int i = n - 2, lower = k + 1; i >= 0; --i) {  // upper hull
    const Eigen::Vector2d& p = pts_[static_cast<std::size_t>(i)];
    while (k >= lower && cross2(stack_[k - 1] - stack_[k - 2], p - stack_[k - 2]) <= kEps) --k;
    stack_[static_cast<std::size_t>(k++)] = p;
  }
  int h = n == 1 ? 1 : k - 1;  // the last point repeats the first
  // coincident points: the chain leaves one or two copies of the same point
  if (h == 2 && (stack_[0] - stack_[1]).norm() < 1e-12) h = 1;
  for (int i = 0; i < h; ++i) pts_[static_cast<std::size_t>(i)] = stack_[static_cast<std::size_t>(i)];
  hull_size_ = h;
  fitEllipse();
  return true;
}

void SupportRegion::fitEllipse() {
  const int h = hull_size_;
  Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  const Eigen::Vector2d p0 = pts_[0];
  double a2 = 0;  // twice the area
  if (h >= 3) {
    // area, centroid and second moments of the polygon, relative to p0 (Green's theorem)
    Eigen::Vector2d m1 = Eigen::Vector2d::Zero();
    double sxx = 0, syy = 0, sxy = 0;
    for (int i = 0; i < h; ++i) {
      const Eigen::Vector2d a = pts_[static_cast<std::size_t>(i)] - p0;
      const Eigen::Vector2d b = pts_[static_cast<std::size_t>((i + 1) % h)] - p0;
      const double c = cross2(a, b);
      a2 += c;
      m1 += c * (a + b);
      sxx += c * (a.x() * a.x() + a.x() * b.x() + b.x() * b.x());
      syy += c * (a.y() * a.y() + a.y() * b.y() + b.y() * b.y());
      sxy += c * (2 * a.x() * a.y() + a.x() * b.y() + b.x() * a.y() + 2 * b.x() * b.y());
    }
    const double area = 0.5 * a2;
    const Eigen::Vector2d c = m1 / (3 * a2);  // (1/(6A)) Σ (a + b) cross
    sigma(0, 0) = sxx / 12 / area - c.x() * c.x();
    sigma(1, 1) = syy / 12 / area - c.y() * c.y();
    sigma(0, 1) = sigma(1, 0) = sxy / 24 / area - c.x() * c.y();
    centre_ = p0 + c;
    area_ = area;
  } else if (h == 2) {
    const Eigen::Vector2d d = pts_[1] - p0;
    centre_ = p0 + 0.5 * d;
    sigma = d * d.transpose() / 12;  // a uniform segment
  } else {
    centre_ = p0;
  }
  const double r2 = options_.min_radius * options_.min_radius;
  if (h < 3) sigma += r2 * Eigen::Matrix2d::Identity();  // a segment or a point
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(sigma);
  // Q = Σ⁻¹ / λ_max(Σ⁻¹) = λ_min(Σ) Σ⁻¹ (Σ's eigenvalues floored at min_radius² for sliver polygons)
  const Eigen::Vector2d ev = eig.eigenvalues().cwiseMax(r2);
  Q_ = ev(0) * (eig.eigenvectors() * ev.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose());
  Q_ = 0.5 * (Q_ + Q_.transpose()).eval();
  double delta2 = 0;
  if (options_.inscribed && h >= 3) {
    const Eigen::Matrix2d Qinv = Q_.inverse();
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < h; ++i) {
      const Eigen::Vector2d a = pts_[static_cast<std::size_t>(i)];
      const Eigen::Vector2d e = pts_[static_cast<std::size_t>((i + 1) % h)] - a;
      const Eigen::Vector2d nout = Eigen::Vector2d(e.y(), -e.x()).normalized();  // outward (ccw hull)
      const double hdist = nout.dot(a - centre_);
      best = std::min(best, hdist / std::sqrt(nout.dot(Qinv * nout)));
    }
    delta2 = best * best;
  } else {
    for (int i = 0; i < h; ++i) {
      const Eigen::Vector2d r = pts_[static_cast<std::size_t>(i)] - centre_;
      delta2 = std::max(delta2, r.dot(Q_ * r));
    }
  }
  delta_ = std::max(std::sqrt(delta2), options_.min_radius);
}

double SupportRegion::polygonDistance(const Eigen::Vector2d& u) const {
  const int h = hull_size_;
  if (h == 0) return kNaN;
  if (h == 1) return -(u - pts_[0]).norm();
  if (h == 2) return -segmentDistance(u, pts_[0], pts_[1]);
  bool inside = true;
  double inner = std::numeric_limits<double>::infinity();
  double outer = std::numeric_limits<double>::infinity();
  for (int i = 0; i < h; ++i) {
    const Eigen::Vector2d& a = pts_[static_cast<std::size_t>(i)];
    const Eigen::Vector2d& b = pts_[static_cast<std::size_t>((i + 1) % h)];
    const double s = cross2(b - a, u - a) / (b - a).norm();  // signed distance to the edge line, > 0 inside
    if (s < 0) inside = false;
    inner = std::min(inner, s);
    outer = std::min(outer, segmentDistance(u, a, b));
  }
  return inside ? inner : -outer;
}

BalanceDistance SupportRegion::distance(const Vector3& com) const {
  BalanceDistance d;
  if (empty() || !com.allFinite()) {
    d.ellipse = d.ellipse_m = d.polygon_m = kNaN;
    return d;
  }
  const Eigen::Vector2d u = project(com);
  const Eigen::Vector2d r = u - centre_;
  d.ellipse = delta_ * delta_ - r.dot(Q_ * r);
  d.ellipse_m = d.ellipse / (2 * delta_);
  d.polygon_m = polygonDistance(u);
  return d;
}

//---- BalanceRows -----------------------------------------------------------------------------

BalanceRows::BalanceRows(int system, const skeleton::Model& model, const skeleton::Data& data,
                         const BalanceOptions& options)
    : system_(system), model_(&model), data_(&data), options_(options), support_(options) {
  if (system < 0) throw std::invalid_argument("balance: system index must be >= 0, got " + std::to_string(system));
  const std::size_t nj = model.joints.size();
  subtree_mass_.assign(nj, 0.0);
  subtree_moment_.assign(nj, Vector3::Zero());
  for (const skeleton::Segment& seg : model.segments) {
    subtree_mass_[static_cast<std::size_t>(seg.joint)] += seg.mass;
    total_mass_ += seg.mass;
  }
  for (std::size_t i = nj; i-- > 0;) {
    const int p = model.joints[i].parent;
    if (p >= 0) subtree_mass_[static_cast<std::size_t>(p)] += subtree_mass_[i];
  }
  if (!(total_mass_ > 0)) throw std::invalid_argument("balance: model '" + model.name + "' has no mass");
  Jcom_.setZero(3, model.nv);
  J_.setZero(model.nv);
  state_.distance = support_.distance(Vector3::Zero());
}

bool BalanceRows::evaluate() {
  const skeleton::Model& model = *model_;
  const skeleton::Data& data = *data_;
  const std::size_t nj = model.joints.size();
  // CoM (3.28) and its Jacobian (3.32–3.36): column k of joint j moves j's subtree rigidly, so
  // Σ m ċ = M_sub v_k + ω_k × (Σ m c) with (ω_k, v_k) the world spatial column at the origin
  for (std::size_t i = 0; i < nj; ++i) subtree_moment_[i].setZero();
  for (const skeleton::Segment& seg : model.segments)
    subtree_moment_[static_cast<std::size_t>(seg.joint)] +=
        seg.mass * data.oMi[static_cast<std::size_t>(seg.joint)].act(seg.com);
  Vector3 moment = Vector3::Zero();
  for (std::size_t i = nj; i-- > 0;) {
    const int p = model.joints[i].parent;
    if (p >= 0)
      subtree_moment_[static_cast<std::size_t>(p)] += subtree_moment_[i];
    else
      moment += subtree_moment_[i];
  }
  state_.com = moment / total_mass_;
  for (std::size_t i = 0; i < nj; ++i) {
    const skeleton::Joint& j = model.joints[i];
    for (int c = j.idx_v; c < j.idx_v + j.nv; ++c)
      Jcom_.col(c) = (subtree_mass_[i] * data.J.col(c).tail<3>() + data.J.col(c).head<3>().cross(subtree_moment_[i])) /
                     total_mass_;
  }
  state_.distance = support_.distance(state_.com);
  if (support_.empty() || !std::isfinite(state_.distance.ellipse)) {
    J_.setZero();
    return false;
  }
  // (3.37) scaled by 1/(2δ): ∂d_m/∂q̇ = −(1/δ) (Q r)ᵀ Eᵀ J_com
  const Eigen::Vector2d r = support_.project(state_.com) - support_.centre();
  const Vector3 g = support_.basis() * (support_.metric() * r);
  J_.noalias() = (-1.0 / support_.delta()) * (g.transpose() * Jcom_);
  return J_.allFinite();
}

void BalanceRows::addRows(int id, double /*dt*/, RowSet& rows) {
  state_.row = -1;
  state_.lambda = 0.0;
  if (!evaluate()) return;
  if (system_ >= rows.numSystems() || rows.systemNv(system_) != J_.size()) return;
  RowInfo info;
  info.kind = RowKind::kUnilateral;
  info.source = RowSource::kBalance;
  info.producer = id;
  info.tag = 0;
  info.distance = state_.distance.ellipse_m;
  info.recovery_speed = options_.recovery_speed;
  info.system_a = system_;
  const int r = rows.add(info);
  if (r < 0) return;
  rows.jacobian(r, system_) = J_;
  state_.row = r;
}

void BalanceRows::solved(int /*id*/, const RowSet& rows) {
  if (state_.row >= 0 && state_.row < rows.size()) state_.lambda = rows.info(state_.row).lambda;
}

}  // namespace mannequin::constraints
