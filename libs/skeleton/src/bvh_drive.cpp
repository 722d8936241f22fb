#include "mannequin/skeleton/bvh_drive.hpp"

#include <cmath>

#include "mannequin/core/config.hpp"
#include "mannequin/skeleton/anthropometry.hpp"  // standingConfiguration
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::skeleton {

using math::Matrix3;

namespace {
constexpr double kRad2Deg = 180.0 / 3.14159265358979323846;

// smallest rotation taking unit direction a onto unit direction b
Matrix3 rotationBetween(const Vector3& a, const Vector3& b) {
  const Vector3 an = a.normalized(), bn = b.normalized();
  const Vector3 c = an.cross(bn);
  const double s = c.norm(), d = an.dot(bn);
  if (s < 1e-12) {
    if (d > 0) return Matrix3::Identity();
    // opposite: half turn about any axis orthogonal to a
    Vector3 axis = an.cross(Vector3::UnitX());
    if (axis.norm() < 1e-6) axis = an.cross(Vector3::UnitY());
    return math::expSO3(axis.normalized() * 3.14159265358979323846);
  }
  return math::expSO3(c / s * std::atan2(s, d));
}

// the joints a segment's orientation sets: from its joint up to (excluding) the first joint
// that carries any segment
std::vector<int> chainOf(const Model& m, int segment, const std::vector<char>& carries) {
  std::vector<int> chain;
  int j = m.segments[segment].joint;
  do {
    chain.insert(chain.begin(), j);
    j = m.joints[j].parent;
  } while (j >= 0 && !carries[j]);
  return chain;
}
}  // namespace

// ---- mapping config -----------------------------------------------------------------------
namespace {
BvhDriveMap readBvhDriveMap(const core::ConfigNode& root) {
  root.allowOnly({"name", "unit", "scale_to_m", "segments"});
  BvhDriveMap map;
  map.name = root.get("name", map.name);
  const auto unit = root.find("unit");
  const auto scale = root.find("scale_to_m");
  if (unit && scale) scale->fail("give either 'unit' or 'scale_to_m', not both");
  if (unit) {
    static const BvhUnit kUnits[] = {BvhUnit::Metre, BvhUnit::Centimetre, BvhUnit::Inch, BvhUnit::Cmu};
    map.unit_scale_to_m = bvhUnitScale(kUnits[unit->choice({"m", "cm", "inch", "cmu"})]);
  }
  if (scale) map.unit_scale_to_m = scale->positive();
  const core::ConfigNode segments = root["segments"];
  for (const std::string& segment : segments.keys()) {
    const core::ConfigNode joint = segments[segment];
    if (!joint.isScalar()) joint.fail("must name one BVH joint");
    map.segments.emplace_back(segment, joint.str());
  }
  if (map.segments.empty()) segments.fail("expected a map of mannequin segments to BVH joints, got none");
  return map;
}
}  // namespace

BvhDriveMap parseBvhDriveMap(const std::string& text, const std::string& source) {
  return readBvhDriveMap(core::ConfigNode::parse(text, source));
}

BvhDriveMap loadBvhDriveMap(const std::string& path) { return readBvhDriveMap(core::ConfigNode::load(path)); }

// ---- calibration --------------------------------------------------------------------------
BvhDriver::BvhDriver(const Model& model, const Bvh& bvh, const BvhDriveMap& map)
    : model_(model), bvh_(bvh), link_of_joint_(model.joints.size(), -1), bvh_world_(bvh.joints.size()) {
  if (!std::isfinite(map.unit_scale_to_m) || map.unit_scale_to_m <= 0)
    throw std::invalid_argument("mapping '" + map.name + "': unit scale must be finite and > 0");
  if (map.segments.empty()) throw std::invalid_argument("mapping '" + map.name + "' maps no segment");
  length_scale_ = map.unit_scale_to_m;
  // BVH world (y up, facing +z, left +x) → mannequin world (z up, facing +x, left +y)
  A_ << 0, 0, 1,
        1, 0, 0,
        0, 1, 0;

  for (const auto& [seg_name, bvh_name] : map.segments) {
    const int s = model.segmentIndex(seg_name);
    const int b = findBvhJoint(bvh, bvh_name);
    if (b < 0)
      throw std::invalid_argument("mapping '" + map.name + "': BVH joint '" + bvh_name + "' (for segment '" +
                                  seg_name + "') is not in " + bvh.source);
    if (link_of_joint_[model.segments[s].joint] >= 0)
      throw std::invalid_argument("mapping '" + map.name + "': segment '" + seg_name + "' is mapped twice");
    link_of_joint_[model.segments[s].joint] = static_cast<int>(links_.size());
    links_.push_back(Link{s, b, Matrix3::Identity(), Matrix3::Identity(), {}});
  }
  // the joints each mapped segment sets, found once
  std::vector<char> carries(model.joints.size(), 0);
  for (const Segment& seg : model.segments) carries[seg.joint] = 1;
  for (Link& L : links_) L.chain = chainOf(model, L.segment, carries);
  if (model.segments[links_[0].segment].joint != 0 || model.joints[0].type != JointType::kFreeFlyer)
    throw std::invalid_argument("mapping '" + map.name + "': the first segment ('" + map.segments[0].first +
                                "') must be carried by the free-flyer root");

  // rest poses: BVH with every channel zero, mannequin at its zero configuration
  const std::vector<double> zero(static_cast<size_t>(bvh.num_channels), 0.0);
  std::vector<math::SE3> rest(bvh.joints.size());
  bvhForwardKinematics(bvh, zero, rest, length_scale_);
  Data data(model);
  forwardKinematics(model, data, model.neutralConfiguration());

  // ancestors in the mapping: a segment's direction points to its first mapped descendant
  for (size_t i = 0; i < links_.size(); ++i) {
    Link& L = links_[i];
    const int j = model.segments[L.segment].joint;
    Vector3 dir_m = Vector3::Zero(), dir_b = Vector3::Zero();
    for (size_t k = 0; k < links_.size() && dir_m.isZero(); ++k) {
      const int jk = model.segments[links_[k].segment].joint;
      // nearest mapped ancestor of jk must be j
      int a = model.joints[jk].parent;
      while (a >= 0 && link_of_joint_[a] < 0) a = model.joints[a].parent;
      if (k != i && a == j) {
        dir_m = data.oMi[jk].p - data.oMi[j].p;
        dir_b = A_ * (rest[links_[k].bvh].p - rest[L.bvh].p);
      }
    }
    if (dir_m.isZero()) {
      // a leaf: the far end of the capsule, and the BVH joint's first child (or End Site)
      const Capsule& c = model.segments[L.segment].capsule;
      dir_m = data.oMi[j].R * (c.a.norm() > c.b.norm() ? c.a : c.b);
      for (size_t k = 0; k < bvh.joints.size(); ++k)
        if (bvh.joints[k].parent == L.bvh) {
          dir_b = A_ * (rest[k].p - rest[L.bvh].p);
          break;
        }
    }
    if (dir_m.norm() > 1e-9 && dir_b.norm() > 1e-9) L.C = rotationBetween(dir_m, dir_b);
    L.rest_inv = rest[L.bvh].R.transpose();
  }

  // hip heights: actor from its rest pose (root above the lowest point), mannequin standing
  double lowest = rest[0].p.y();
  for (const auto& H : rest) lowest = std::min(lowest, H.p.y());
  const double actor_hip = rest[0].p.y() - lowest;
  const VectorX standing = standingConfiguration(model);
  const double mannequin_hip = standing(model.joints[0].idx_q + 2);
  scale_ = actor_hip > 1e-6 ? mannequin_hip / actor_hip : 1.0;
}

std::vector<std::string> BvhDriver::segmentNames() const {
  std::vector<std::string> names;
  for (const Link& L : links_) names.push_back(model_.segments[L.segment].name);
  return names;
}

// ---- one frame ----------------------------------------------------------------------------
BvhDriveFrame BvhDriver::drive(long long frame_index) {
  const int f = resolveBvhFrame(bvh_, frame_index);
  bvhForwardKinematics(bvh_, bvhFrame(bvh_, f), bvh_world_, length_scale_);

  // world orientation asked of each mapped segment
  std::vector<Matrix3> target(links_.size());
  for (size_t i = 0; i < links_.size(); ++i) {
    const Link& L = links_[i];
    target[i] = A_ * bvh_world_[L.bvh].R * L.rest_inv * A_.transpose() * L.C;
  }

  BvhDriveFrame out;
  out.q = model_.neutralConfiguration();
  std::vector<Matrix3> oRi(model_.joints.size(), Matrix3::Identity());

  // walk the tree; each mapped segment sets the joints of its chain
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& J = model_.joints[j];
    const int li = link_of_joint_[j];
    if (li >= 0) {
      const Link& L = links_[li];
      const std::vector<int>& chain = L.chain;
      const int parent = model_.joints[chain.front()].parent;
      const Matrix3 R_parent = parent >= 0 ? oRi[parent] : Matrix3::Identity();
      const Matrix3 R_rel = (R_parent).transpose() * target[li];
      if (chain.size() == 1 && J.type == JointType::kFreeFlyer) {
        out.q.segment<3>(J.idx_q) = scale_ * (A_ * bvh_world_[L.bvh].p);
        out.q.segment<3>(J.idx_q + 3) = math::logSO3(J.placement.R.transpose() * R_rel);
      } else if (chain.size() == 1 && J.type == JointType::kBall) {
        out.q.segment<3>(J.idx_q) = math::logSO3(J.placement.R.transpose() * R_rel);
      } else {
        // revolute chain: Gauss–Newton on log(R(θ)ᵀ R_rel), started from the projection
        const size_t n = chain.size();
        Eigen::VectorXd th(n);
        const Vector3 w0 = math::logSO3(R_rel);
        for (size_t k = 0; k < n; ++k) th(k) = model_.joints[chain[k]].axis.dot(w0);
        for (int it = 0; it < 8; ++it) {
          Matrix3 R = Matrix3::Identity();
          std::vector<Matrix3> after(n + 1, Matrix3::Identity());  // product of factors after k
          std::vector<Matrix3> factor(n);
          for (size_t k = 0; k < n; ++k) {
            const Joint& Jk = model_.joints[chain[k]];
            factor[k] = Jk.placement.R * math::expSO3(Jk.axis * th(k));
            R = R * factor[k];
          }
          for (size_t k = n; k-- > 0;) after[k] = factor[k] * after[k + 1];
          const Vector3 e = math::logSO3(R.transpose() * R_rel);
          if (e.norm() < 1e-12) break;
          Eigen::Matrix<double, 3, Eigen::Dynamic> Jb(3, n);
          for (size_t k = 0; k < n; ++k) Jb.col(k) = after[k + 1].transpose() * model_.joints[chain[k]].axis;
          th += (Jb.transpose() * Jb + 1e-9 * Eigen::MatrixXd::Identity(n, n)).ldlt().solve(Jb.transpose() * e);
        }
        for (size_t k = 0; k < n; ++k) out.q(model_.joints[chain[k]].idx_q) = th(k);
      }
      // limits, then the chain's world orientations again (its first joints were visited
      // before this segment's joint set their coordinates)
      for (int c : chain) {
        const Joint& Jc = model_.joints[c];
        for (int k = Jc.idx_q; k < Jc.idx_q + Jc.nq; ++k) {
          const double clamped = std::clamp(out.q(k), model_.lower_limit(k), model_.upper_limit(k));
          if (clamped != out.q(k)) ++out.clamped;
          out.q(k) = clamped;
        }
        const SE3 local = jointTransform(Jc, out.q.data() + Jc.idx_q);
        oRi[c] = Jc.parent >= 0 ? Matrix3(oRi[Jc.parent] * local.R) : local.R;
      }
    }
    // orientation of joint j with the coordinates set so far
    const SE3 local = jointTransform(J, out.q.data() + J.idx_q);
    oRi[j] = J.parent >= 0 ? Matrix3(oRi[J.parent] * local.R) : local.R;
  }

  // tracking error of each mapped segment after the limits
  double sum = 0;
  for (size_t i = 0; i < links_.size(); ++i) {
    const double err = math::logSO3(oRi[model_.segments[links_[i].segment].joint].transpose() * target[i]).norm() * kRad2Deg;
    out.error_deg.push_back(err);
    out.max_error_deg = std::max(out.max_error_deg, err);
    sum += err;
  }
  out.mean_error_deg = sum / static_cast<double>(links_.size());
  return out;
}

}  // namespace mannequin::skeleton
