#include "mannequin/skeleton/model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mannequin::skeleton {

namespace {
[[noreturn]] void fail(const std::string& msg) { throw std::invalid_argument(msg); }

template <class Items>
int findByName(const Items& items, const std::string& name) {
  for (size_t i = 0; i < items.size(); ++i)
    if (items[i].name == name) return static_cast<int>(i);
  return -1;
}

template <class Items>
std::string listNames(const Items& items) {
  std::string out;
  for (size_t i = 0; i < items.size() && i < 60; ++i) out += (i ? ", " : "") + items[i].name;
  if (items.size() > 60) out += ", ...";
  return out;
}
}  // namespace

const char* toString(JointType type) {
  switch (type) {
    case JointType::kRevolute: return "revolute";
    case JointType::kBall: return "ball";
    case JointType::kFreeFlyer: return "free_flyer";
  }
  return "?";
}

int Model::addJoint(const std::string& jname, JointType type, int parent, const SE3& placement,
                    const Vector3& axis) {
  if (jname.empty()) fail("joint name is empty");
  if (findJoint(jname) >= 0) fail("joint '" + jname + "' is defined twice");
  if (parent < -1 || parent >= static_cast<int>(joints.size()))
    fail("joint '" + jname + "': parent index " + std::to_string(parent) + " does not exist");
  if (!placement.allFinite() || !math::isRotation(placement.R, 1e-6))
    fail("joint '" + jname + "': placement is not a finite rigid transform");
  if (type == JointType::kFreeFlyer && (parent != -1 || !joints.empty()))
    fail("joint '" + jname + "': a free flyer must be the first joint, attached to the world");
  Joint j;
  j.name = jname;
  j.type = type;
  j.parent = parent;
  j.placement = placement;
  if (type == JointType::kRevolute) {
    if (!axis.allFinite() || axis.norm() < 1e-9) fail("joint '" + jname + "': revolute axis is zero or not finite");
    j.axis = axis.normalized();
  }
  j.nq = j.nv = (type == JointType::kRevolute ? 1 : type == JointType::kBall ? 3 : 6);
  j.idx_q = nq;
  j.idx_v = nv;
  nq += j.nq;
  nv += j.nv;
  joints.push_back(j);
  // limits: none by default
  lower_limit.conservativeResize(nq);
  upper_limit.conservativeResize(nq);
  lower_limit.tail(j.nq).setConstant(-std::numeric_limits<double>::infinity());
  upper_limit.tail(j.nq).setConstant(std::numeric_limits<double>::infinity());
  // support chain
  std::vector<int> chain = parent >= 0 ? support[parent] : std::vector<int>{};
  chain.push_back(static_cast<int>(joints.size()) - 1);
  support.push_back(std::move(chain));
  return static_cast<int>(joints.size()) - 1;
}

int Model::addSegment(const Segment& s) {
  if (s.name.empty()) fail("segment name is empty");
  if (findSegment(s.name) >= 0) fail("segment '" + s.name + "' is defined twice");
  if (s.joint < 0 || s.joint >= static_cast<int>(joints.size()))
    fail("segment '" + s.name + "': joint index " + std::to_string(s.joint) + " does not exist");
  if (!std::isfinite(s.mass) || s.mass < 0) fail("segment '" + s.name + "': mass must be finite and >= 0");
  if (!s.com.allFinite() || !s.inertia.allFinite() || !s.inertia.isApprox(s.inertia.transpose(), 1e-9))
    fail("segment '" + s.name + "': centre of mass or inertia is not finite/symmetric");
  if (!std::isfinite(s.capsule.radius) || s.capsule.radius < 0 || !s.capsule.a.allFinite() || !s.capsule.b.allFinite())
    fail("segment '" + s.name + "': capsule radius must be finite and >= 0");
  segments.push_back(s);
  return static_cast<int>(segments.size()) - 1;
}

int Model::addFrame(const std::string& fname, int joint, const SE3& placement) {
  if (fname.empty()) fail("frame name is empty");
  if (findFrame(fname) >= 0) fail("frame '" + fname + "' is defined twice");
  if (joint < 0 || joint >= static_cast<int>(joints.size()))
    fail("frame '" + fname + "': joint index " + std::to_string(joint) + " does not exist");
  if (!placement.allFinite()) fail("frame '" + fname + "': placement is not finite");
  frames.push_back(Frame{fname, joint, placement});
  return static_cast<int>(frames.size()) - 1;
}

void Model::setLimits(int idx_q, double lower, double upper) {
  if (idx_q < 0 || idx_q >= nq) fail("limit index " + std::to_string(idx_q) + " is outside [0, nq)");
  if (std::isnan(lower) || std::isnan(upper) || lower > upper)
    fail("coordinate " + std::to_string(idx_q) + ": limits [" + std::to_string(lower) + ", " +
         std::to_string(upper) + "] are not an interval");
  lower_limit(idx_q) = lower;
  upper_limit(idx_q) = upper;
}

void Model::setBallLimit(int joint, const BallLimit& limit) {
  if (joint < 0 || joint >= static_cast<int>(joints.size())) fail("ball limit: joint index " + std::to_string(joint) + " does not exist");
  if (joints[joint].type != JointType::kBall) fail("joint '" + joints[joint].name + "' is not a ball joint: no swing/twist limits");
  const std::string err = checkBallLimit(limit);
  if (!err.empty()) fail("joint '" + joints[joint].name + "': swing/twist limits: " + err);
  joints[joint].ball_limit = limit;
  joints[joint].ball_limit.enabled = true;
}

double BallLimit::maxSwing() const {
  double m = 0.0;
  constexpr int kSamples = 720;
  for (int i = 0; i < kSamples; ++i) {
    const double phi = 2.0 * 3.14159265358979323846 * i / kSamples;
    m = std::max(m, std::hypot(swing_cx + swing_a * std::cos(phi), swing_cy + swing_b * std::sin(phi)));
  }
  return m;
}

std::string checkBallLimit(const BallLimit& l) {
  const double vals[] = {l.swing_a, l.swing_b, l.swing_cx, l.swing_cy, l.twist_lower, l.twist_upper};
  for (double v : vals)
    if (!std::isfinite(v)) return "a value is not finite";
  if (!l.twist_axis.allFinite() || !l.swing_x.allFinite() || !l.swing_y.allFinite()) return "an axis is not finite";
  constexpr double kTol = 1e-9;
  if (std::abs(l.twist_axis.norm() - 1) > kTol || std::abs(l.swing_x.norm() - 1) > kTol ||
      std::abs(l.swing_y.norm() - 1) > kTol)
    return "the twist axis and the swing axes must be unit vectors";
  if (std::abs(l.twist_axis.dot(l.swing_x)) > kTol || std::abs(l.twist_axis.dot(l.swing_y)) > kTol ||
      std::abs(l.swing_x.dot(l.swing_y)) > kTol)
    return "the twist axis and the swing axes must be orthogonal";
  if (l.swing_a <= 0 || l.swing_b <= 0) return "the swing ellipse's semi-axes must be > 0";
  const double cx = l.swing_cx / l.swing_a, cy = l.swing_cy / l.swing_b;
  if (cx * cx + cy * cy >= 1.0) return "the swing ellipse must contain the rest direction (swing 0)";
  if (l.maxSwing() > BallLimit::kMaxSwing + 1e-9)
    return "the swing ellipse reaches " + std::to_string(l.maxSwing() * 180 / 3.14159265358979323846) +
           " deg, past the 150 deg allowed (the swing/twist decomposition is singular at 180 deg and its "
           "limit rows lose their accuracy well before)";
  if (!(l.twist_lower <= 0 && 0 <= l.twist_upper)) return "the twist range [lower, upper] must contain 0";
  if (l.twist_lower < -BallLimit::kMaxTwist - 1e-9 || l.twist_upper > BallLimit::kMaxTwist + 1e-9)
    return "the twist range must stay within [-170, 170] deg (the twist angle wraps at 180 deg)";
  return {};
}

void swingBasis(const Vector3& t, Vector3& e1, Vector3& e2) {
  const bool along_x = std::abs(t.x()) > 0.9;
  const Vector3 a = along_x ? Vector3::UnitY() : Vector3::UnitX();
  const Vector3 b = along_x ? Vector3::UnitZ() : Vector3::UnitY();
  e1 = (a - a.dot(t) * t).normalized();
  e2 = (b - b.dot(t) * t - b.dot(e1) * e1).normalized();
}

int Model::findJoint(const std::string& n) const { return findByName(joints, n); }
int Model::findSegment(const std::string& n) const { return findByName(segments, n); }
int Model::findFrame(const std::string& n) const { return findByName(frames, n); }

int Model::jointIndex(const std::string& n) const {
  const int i = findJoint(n);
  if (i < 0) fail("unknown joint '" + n + "' in mannequin '" + name + "' (joints: " + listNames(joints) + ")");
  return i;
}
int Model::segmentIndex(const std::string& n) const {
  const int i = findSegment(n);
  if (i < 0) fail("unknown segment '" + n + "' in mannequin '" + name + "' (segments: " + listNames(segments) + ")");
  return i;
}
int Model::frameIndex(const std::string& n) const {
  const int i = findFrame(n);
  if (i < 0) fail("unknown frame '" + n + "' in mannequin '" + name + "' (frames: " + listNames(frames) + ")");
  return i;
}

double Model::totalMass() const {
  double m = 0;
  for (const auto& s : segments) m += s.mass;
  return m;
}

std::vector<int> Model::velocityParents() const {
  std::vector<int> p(static_cast<std::size_t>(nv), -1);
  for (const Joint& j : joints) {
    const int up = j.parent >= 0 ? joints[static_cast<std::size_t>(j.parent)].idx_v + joints[static_cast<std::size_t>(j.parent)].nv - 1 : -1;
    for (int k = 0; k < j.nv; ++k) p[static_cast<std::size_t>(j.idx_v + k)] = k == 0 ? up : j.idx_v + k - 1;
  }
  return p;
}

std::vector<std::string> Model::coordinateNames() const {
  std::vector<std::string> names;
  names.reserve(nq);
  for (const auto& j : joints) {
    switch (j.type) {
      case JointType::kRevolute: names.push_back(j.name); break;
      case JointType::kBall:
        for (const char* c : {".x", ".y", ".z"}) names.push_back(j.name + c);
        break;
      case JointType::kFreeFlyer:
        for (const char* c : {".px", ".py", ".pz", ".rx", ".ry", ".rz"}) names.push_back(j.name + c);
        break;
    }
  }
  return names;
}

Data::Data(const Model& model)
    : liMi(model.joints.size()),
      oMi(model.joints.size()),
      oMf(model.frames.size()),
      J(Matrix6X::Zero(6, model.nv)),
      Jcom(Matrix3X::Zero(3, model.nv)),
      segment_com(model.segments.size(), Vector3::Zero()),
      subtree_mass(model.joints.size(), 0.0),
      subtree_moment(model.joints.size(), Vector3::Zero()),
      joint_twist(model.joints.size(), Vector6::Zero()),
      joint_accel(model.joints.size(), Vector6::Zero()),
      joint_wrench(model.joints.size(), Vector6::Zero()),
      tau(VectorX::Zero(model.nv)) {}

}  // namespace mannequin::skeleton
