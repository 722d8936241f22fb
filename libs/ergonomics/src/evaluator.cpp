// Angles measured on the skeleton after forward kinematics (docs/ergonomics.md, "How each angle is
// measured"), joint-limit proximity and reach.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::ergonomics {

namespace {
constexpr double kRad2Deg = 180.0 / 3.14159265358979323846;

double clamp1(double x) { return std::clamp(x, -1.0, 1.0); }
double angleBetween(const Vector3& a, const Vector3& b) { return std::acos(clamp1(a.dot(b))) * kRad2Deg; }

/// Twist of rotation R about `axis` (unit), swing–twist decomposition, degrees in (−180, 180].
double twistAbout(const skeleton::Matrix3& R, const Vector3& axis) {
  const Eigen::Quaterniond q(R);
  double deg = 2.0 * std::atan2(q.vec().dot(axis), q.w()) * kRad2Deg;
  if (deg > 180.0) deg -= 360.0;
  if (deg <= -180.0) deg += 360.0;
  return deg;
}

/// Direction of the clavicle (sternoclavicular joint → shoulder joint) above the thorax's transverse plane.
double clavicleElevation(const Vector3& c) {
  return std::atan2(c.z(), std::hypot(c.x(), c.y())) * kRad2Deg;
}
}  // namespace

Evaluator::Evaluator(const skeleton::Model& model, const Thresholds& thresholds)
    : model_(model), thresholds_(thresholds), data_(model) {
  checkThresholds(thresholds);
  const auto joint = [&](const std::string& name) {
    const int j = model.findJoint(name);
    if (j < 0)
      throw std::invalid_argument("ergonomics: model '" + model.name + "' has no joint '" + name +
                                  "' (the mannequin of skeleton::buildMannequin is expected)");
    return j;
  };
  const auto frame = [&](const std::string& name) {
    const int f = model.findFrame(name);
    if (f < 0) throw std::invalid_argument("ergonomics: model '" + model.name + "' has no frame '" + name + "'");
    return f;
  };
  root_ = joint("root");
  if (model.joints[root_].type != skeleton::JointType::kFreeFlyer)
    throw std::invalid_argument("ergonomics: model '" + model.name + "': joint 'root' is not a free flyer");
  thoracic_ = joint("thoracic");
  neck_ = joint("neck");
  head_top_ = frame("head_top");
  for (int s = 0; s < 2; ++s) {
    const std::string x = s == 0 ? "_l" : "_r";
    ArmIds& a = arm_[s];
    a.clavicle = joint("sternoclavicular" + x);
    a.shoulder = joint("shoulder" + x);
    a.elbow = joint("elbow" + x);
    a.radioulnar = joint("radioulnar" + x);
    a.wrist = joint("wrist" + x);
    a.wrist_dev = joint("wrist_deviation" + x);
    a.palm = frame("palm" + x);
    hip_[s] = joint("hip" + x);
    knee_[s] = joint("knee" + x);
    ankle_[s] = joint("ankle" + x);
    // arm length: shoulder → elbow → wrist → palm, straight (the joint placements along the chain)
    arm_length_[s] = model.joints[a.elbow].placement.p.norm() + model.joints[a.radioulnar].placement.p.norm() +
                     model.joints[a.wrist].placement.p.norm() + model.joints[a.wrist_dev].placement.p.norm() +
                     model.frames[a.palm].placement.p.norm();
    // clavicle's rest direction (its elevation in the thorax frame at q = 0)
    clavicle_rest_deg_[s] = clavicleElevation(model.joints[a.shoulder].placement.p.normalized());
  }
}

void Evaluator::checkQ(const VectorX& q) const {
  if (q.size() != model_.nq)
    throw std::invalid_argument("ergonomics: q has " + std::to_string(q.size()) + " coordinates, model '" +
                                model_.name + "' has " + std::to_string(model_.nq));
  for (int i = 0; i < q.size(); ++i)
    if (!std::isfinite(q(i))) {
      const auto names = model_.coordinateNames();
      throw std::invalid_argument("ergonomics: q(" + std::to_string(i) + ") '" + names[i] + "' is not finite");
    }
}

PostureAngles Evaluator::measure(const VectorX& q) {
  checkQ(q);
  skeleton::forwardKinematics(model_, data_, q);
  return angles(data_);
}

PostureAngles Evaluator::measure(const skeleton::Data& data) {
  if (data.oMi.size() != model_.joints.size() || data.oMf.size() != model_.frames.size())
    throw std::invalid_argument("ergonomics: the kinematics data has " + std::to_string(data.oMi.size()) + " joints and " +
                                std::to_string(data.oMf.size()) + " frames, the model '" + model_.name + "' " +
                                std::to_string(model_.joints.size()) + " and " + std::to_string(model_.frames.size()));
  for (std::size_t i = 0; i < data.oMi.size(); ++i)
    if (!data.oMi[i].R.allFinite() || !data.oMi[i].p.allFinite())
      throw std::invalid_argument("ergonomics: the pose of joint '" + model_.joints[i].name + "' is not finite");
  for (std::size_t i = 0; i < data.oMf.size(); ++i)
    if (!data.oMf[i].R.allFinite() || !data.oMf[i].p.allFinite())
      throw std::invalid_argument("ergonomics: the pose of frame '" + model_.frames[i].name + "' is not finite");
  return angles(data);
}

Assessment Evaluator::evaluate(const skeleton::Data& data, const TaskInput& input) {
  checkTaskInput(input);
  Assessment r;
  r.angles = measure(data);
  for (Side s : {Side::kLeft, Side::kRight}) {
    r.rula[static_cast<int>(s)] = scoreRula(r.angles, s, input);
    r.reba[static_cast<int>(s)] = scoreReba(r.angles, s, input);
  }
  return r;
}

PostureAngles Evaluator::angles(const skeleton::Data& data) const {
  const auto& oMi = data.oMi;
  const Thresholds& t = thresholds_;
  PostureAngles out;
  out.neutral_deg = t.neutral_deg;

  // the body's sagittal plane: the pelvis's forward (x) axis made horizontal
  const skeleton::Matrix3& Rp = oMi[root_].R;
  const skeleton::Matrix3& Rt = oMi[thoracic_].R;
  const Vector3 up = Vector3::UnitZ();
  Vector3 fwd(Rp(0, 0), Rp(1, 0), 0.0);
  if (fwd.norm() < 1e-6) fwd = Vector3(Rt(0, 0), Rt(1, 0), 0.0);  // pelvis x vertical: use the thorax's
  if (fwd.norm() < 1e-6) fwd = Vector3::UnitX();
  fwd.normalize();
  const Vector3 left = up.cross(fwd);

  // trunk: the thorax's long axis (thoracic joint → neck base) against the world vertical
  BodyAngles& b = out.body;
  const Vector3 u = Rt.col(2);
  b.trunk_flexion_deg = std::atan2(u.dot(fwd), u.dot(up)) * kRad2Deg;
  b.trunk_side_bend_deg = std::asin(clamp1(u.dot(left))) * kRad2Deg;
  b.trunk_twist_deg = twistAbout(Rp.transpose() * Rt, Vector3::UnitZ());
  b.trunk_twisted = std::abs(b.trunk_twist_deg) > t.twist_deg;
  b.trunk_side_bent = std::abs(b.trunk_side_bend_deg) > t.side_bend_deg;

  // neck: the head's long axis (neck joint → vertex) in the thorax frame
  const skeleton::Matrix3 Rn = Rt.transpose() * oMi[neck_].R;
  const Vector3 h = Rt.transpose() * (data.oMf[head_top_].p - oMi[neck_].p).normalized();
  b.neck_flexion_deg = std::atan2(h.x(), h.z()) * kRad2Deg;
  b.neck_side_bend_deg = std::asin(clamp1(h.y())) * kRad2Deg;
  b.neck_twist_deg = twistAbout(Rn, Vector3::UnitZ());
  b.neck_twisted = std::abs(b.neck_twist_deg) > t.twist_deg;
  b.neck_side_bent = std::abs(b.neck_side_bend_deg) > t.side_bend_deg;

  for (int s = 0; s < 2; ++s) {
    // knees: angle between thigh (hip → knee) and shank (knee → ankle)
    const Vector3 thigh = (oMi[knee_[s]].p - oMi[hip_[s]].p).normalized();
    const Vector3 shank = (oMi[ankle_[s]].p - oMi[knee_[s]].p).normalized();
    b.knee_flexion_deg[s] = angleBetween(thigh, shank);

    // arms, in the thorax frame (origin at the thoracic joint; y = 0 is the midsagittal plane)
    const ArmIds& id = arm_[s];
    const double out_sign = s == 0 ? 1.0 : -1.0;  // +y is the left side
    const auto local = [&](const Vector3& p) -> Vector3 { return Rt.transpose() * (p - oMi[thoracic_].p); };
    const Vector3 pc = local(oMi[id.clavicle].p), ps = local(oMi[id.shoulder].p), pe = local(oMi[id.elbow].p);
    const Vector3 pw = local(oMi[id.wrist].p);
    ArmAngles& a = out.arm[s];
    const Vector3 ua = (pe - ps).normalized();
    const double elevation = std::acos(clamp1(-ua.z())) * kRad2Deg;
    const bool backward = ua.x() < 0 && -ua.x() > std::abs(ua.y());
    a.upper_arm_flexion_deg = backward ? -elevation : elevation;
    a.upper_arm_abduction_deg = std::asin(clamp1(out_sign * ua.y())) * kRad2Deg;
    a.arm_abducted = a.upper_arm_abduction_deg > t.abduction_deg;
    a.shoulder_elevation_deg = clavicleElevation((ps - pc).normalized()) - clavicle_rest_deg_[s];
    a.shoulder_raised = a.shoulder_elevation_deg > t.shoulder_raised_deg;

    const Vector3 fa = (pw - pe).normalized();
    a.elbow_flexion_deg = angleBetween(ua, fa);
    a.shoulder_lateral_m = out_sign * ps.y();
    a.wrist_lateral_m = out_sign * pw.y();
    a.across_midline = a.wrist_lateral_m < 0;
    a.out_to_side = a.wrist_lateral_m - a.shoulder_lateral_m > t.out_to_side_m;

    // wrist: the hand's long axis in the forearm frame (after pronation); flexion toward the palm (+x)
    const skeleton::Matrix3& Rf = oMi[id.radioulnar].R;
    const Vector3 hand = -(Rf.transpose() * oMi[id.wrist_dev].R).col(2);
    a.wrist_flexion_deg = std::atan2(hand.x(), -hand.z()) * kRad2Deg;
    a.wrist_deviation_deg = out_sign * std::asin(clamp1(hand.y())) * kRad2Deg;
    a.wrist_deviated = std::abs(a.wrist_deviation_deg) > t.wrist_deviation_deg;

    // forearm rotation: the forearm frame against the elbow frame about the forearm's long axis
    // (pronation turns about −z on the left, +z on the right: the mirror image)
    const skeleton::Matrix3 Rrel = oMi[id.elbow].R.transpose() * Rf;
    a.forearm_rotation_deg = -out_sign * twistAbout(Rrel, Vector3::UnitZ());
    const int iq = model_.joints[id.radioulnar].idx_q;
    const double lo = model_.lower_limit(iq) * kRad2Deg, hi = model_.upper_limit(iq) * kRad2Deg;
    if (std::isfinite(lo) && std::isfinite(hi) && hi > lo) {
      a.forearm_rotation_fraction = (a.forearm_rotation_deg - lo) / (hi - lo);
      a.wrist_twist_at_end = std::abs(a.forearm_rotation_fraction - 0.5) > 0.5 * t.twist_mid_fraction;
    }
  }
  return out;
}

Assessment Evaluator::evaluate(const VectorX& q, const TaskInput& input) {
  checkTaskInput(input);
  Assessment r;
  r.angles = measure(q);
  for (Side s : {Side::kLeft, Side::kRight}) {
    r.rula[static_cast<int>(s)] = scoreRula(r.angles, s, input);
    r.reba[static_cast<int>(s)] = scoreReba(r.angles, s, input);
  }
  return r;
}

JointLimitReport Evaluator::jointLimits(const VectorX& q) const {
  checkQ(q);
  JointLimitReport rep;
  for (const skeleton::Joint& j : model_.joints) {
    JointLimitUse use;
    use.joint = j.name;
    bool any = false;
    for (int k = j.idx_q; k < j.idx_q + j.nq; ++k) {
      const double lo = model_.lower_limit(k), hi = model_.upper_limit(k);
      if (!std::isfinite(lo) || !std::isfinite(hi) || hi <= lo) continue;
      double f;
      if (lo <= 0 && hi >= 0) {
        if (q(k) >= 0) f = hi > 0 ? q(k) / hi : (q(k) > 0 ? 1e9 : 0.0);
        else f = lo < 0 ? q(k) / lo : 1e9;
      } else {
        f = (q(k) - lo) / (hi - lo);  // 0 outside the range: the position in the range
      }
      if (!any || f > use.fraction) {
        use.fraction = f;
        use.coordinate = k;
      }
      any = true;
    }
    if (!any) continue;
    rep.joints.push_back(use);
    if (rep.worst < 0 || use.fraction > rep.joints[rep.worst].fraction)
      rep.worst = static_cast<int>(rep.joints.size()) - 1;
  }
  return rep;
}

ReachResult Evaluator::reach(const VectorX& q, Side side, const Vector3& target) {
  if (!target.allFinite()) throw std::invalid_argument("ergonomics: reach target is not finite");
  checkQ(q);
  skeleton::forwardKinematics(model_, data_, q);
  const int s = static_cast<int>(side);
  ReachResult r;
  r.shoulder = data_.oMi[arm_[s].shoulder].p;
  r.distance = (target - r.shoulder).norm();
  r.arm_length = arm_length_[s];
  r.miss = std::max(0.0, r.distance - r.arm_length);
  r.reachable = r.distance <= r.arm_length;
  return r;
}

}  // namespace mannequin::ergonomics
