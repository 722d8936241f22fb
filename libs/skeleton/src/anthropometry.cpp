#include "mannequin/skeleton/anthropometry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::skeleton {

namespace {
constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
constexpr double kPi = 3.14159265358979323846;

// ---- de Leva (1996) Table 4 -------------------------------------------------------------
// mass: fraction of body mass; com: CoM position as a fraction of the length from the
// ORIGIN endpoint (cranial for head/trunk, proximal for limbs, heel for the foot);
// rg_*: radii of gyration as fractions of the length about the sagittal (x), transverse (y)
// and longitudinal (z) axes; length: segment length of the reference sample (m).
struct SegmentParams {
  double mass, com, rg_sag, rg_trans, rg_long, length;
};
struct Table {
  double stature;  // reference stature of the sample (m)
  SegmentParams head, upper_trunk, mid_trunk, lower_trunk, upper_arm, forearm, hand, thigh, shank, foot;
};
// lengths: de Leva Table 4 (head: VERT–CERV is replaced by the remainder to the vertex,
// hand: WJC–DA3 from Drillis & Contini 0.108 H); see docs/mannequin-model.md
const Table kMale{1.741,
                  {0.0694, 0.5002, 0.303, 0.315, 0.261, 0.0},
                  {0.1596, 0.5066, 0.505, 0.320, 0.465, 0.1707},
                  {0.1633, 0.4502, 0.482, 0.383, 0.468, 0.2155},
                  {0.1117, 0.6115, 0.615, 0.551, 0.587, 0.1457},
                  {0.0271, 0.5772, 0.285, 0.269, 0.158, 0.2817},
                  {0.0162, 0.4574, 0.276, 0.265, 0.121, 0.2689},
                  {0.0061, 0.3624, 0.288, 0.235, 0.184, 0.108 * 1.741},
                  {0.1416, 0.4095, 0.329, 0.329, 0.149, 0.4222},
                  {0.0433, 0.4459, 0.255, 0.249, 0.103, 0.4340},
                  {0.0137, 0.4415, 0.257, 0.245, 0.124, 0.2581}};
const Table kFemale{1.735,
                    {0.0669, 0.4841, 0.271, 0.295, 0.261, 0.0},
                    {0.1545, 0.5050, 0.466, 0.314, 0.449, 0.1425},
                    {0.1465, 0.4512, 0.433, 0.354, 0.415, 0.2053},
                    {0.1247, 0.4920, 0.433, 0.402, 0.444, 0.1815},
                    {0.0255, 0.5754, 0.278, 0.260, 0.148, 0.2751},
                    {0.0138, 0.4559, 0.261, 0.257, 0.094, 0.2643},
                    {0.0056, 0.3427, 0.244, 0.208, 0.184, 0.108 * 1.735},
                    {0.1478, 0.3612, 0.369, 0.364, 0.162, 0.3685},
                    {0.0481, 0.4416, 0.271, 0.267, 0.093, 0.4323},
                    {0.0129, 0.4014, 0.299, 0.279, 0.124, 0.2283}};

// ---- Drillis & Contini (1966), fractions of stature ---------------------------------------
constexpr double kAnkleHeight = 0.039;     // lateral malleolus height
constexpr double kHipHalfWidth = 0.0535;   // half the distance between hip joint centres
constexpr double kShoulderHalfWidth = 0.110;  // half the distance between shoulder joint centres
constexpr double kShoulderDrop = 0.015;    // shoulder joint centre below the suprasternale
constexpr double kHeelToAnkle = 0.22;      // ankle joint centre from the heel, fraction of foot length
constexpr double kToeJoint = 0.75;         // metatarsophalangeal joint from the heel, fraction of foot length

// ---- AAOS (1965) ranges of motion, degrees ---------------------------------------------
// ball joints: [min, max] per component of the rotation vector in the joint frame, LEFT side
struct BallLimits {
  double x[2], y[2], z[2];
};
// trunk (thoracolumbar flexion 80, extension 25, lateral bending 35, rotation 45) split in two
const BallLimits kLumbar{{-17.5, 17.5}, {-12.5, 40}, {-22.5, 22.5}};
const BallLimits kThoracic{{-17.5, 17.5}, {-12.5, 40}, {-22.5, 22.5}};
// cervical: flexion 45, extension 45, lateral bending 45, rotation 60
const BallLimits kNeck{{-45, 45}, {-45, 45}, {-60, 60}};
// shoulder: abduction 180 (+x), adduction 30, flexion 180 (−y), extension 60, internal 70 (−z), external 90
// (180° capped at 170° to stay clear of the rotation-vector singularity at π)
const BallLimits kShoulder{{-30, 170}, {-170, 60}, {-70, 90}};
// hip: abduction 45 (+x), adduction 30, flexion 120 (−y), extension 30, internal 45 (−z), external 45
const BallLimits kHip{{-30, 45}, {-120, 30}, {-45, 45}};

// ---- helpers ----------------------------------------------------------------------------
Vector3 mirror(const Vector3& v) { return Vector3(v.x(), -v.y(), v.z()); }
// a rotation axis is a pseudo-vector: its mirror image through the sagittal plane
Vector3 mirrorAxis(const Vector3& a) { return Vector3(-a.x(), a.y(), -a.z()); }

SE3 at(const Vector3& p) { return SE3(math::Matrix3::Identity(), p); }

struct Builder {
  Model& model;
  const MannequinSpec& spec;
  double density;

  double radiusFor(double mass, double length) const {
    if (mass <= 0 || length <= 0) return 0.0;
    return std::sqrt(mass / (density * kPi * length));
  }

  // segment along the joint frame from `a` to `b`; com at fraction `c` from `a`
  void segment(const std::string& name, int joint, const SegmentParams& t, double length, const Vector3& a,
               const Vector3& b, double radius = -1.0) {
    Segment s;
    s.name = name;
    s.joint = joint;
    s.mass = t.mass * spec.mass;
    s.length = length;
    s.com = a + t.com * (b - a);
    s.inertia = s.mass * Vector3(std::pow(t.rg_sag * length, 2), std::pow(t.rg_trans * length, 2),
                                 std::pow(t.rg_long * length, 2)).asDiagonal();
    s.capsule.a = a;
    s.capsule.b = b;
    s.capsule.radius = radius >= 0 ? radius : radiusFor(s.mass, length);
    model.addSegment(s);
  }

  void massless(const std::string& name, int joint, const Vector3& a, const Vector3& b, double radius) {
    Segment s;
    s.name = name;
    s.joint = joint;
    s.length = (b - a).norm();
    s.capsule.a = a;
    s.capsule.b = b;
    s.capsule.radius = radius;
    model.addSegment(s);
  }

  void ballLimits(int joint, const BallLimits& l, bool right) {
    const int i = model.joints[joint].idx_q;
    // mirroring a rotation vector negates its x and z components
    const auto set = [&](int k, const double* r, bool flip) {
      if (flip) model.setLimits(i + k, -r[1] * kRadPerDeg, -r[0] * kRadPerDeg);
      else model.setLimits(i + k, r[0] * kRadPerDeg, r[1] * kRadPerDeg);
    };
    set(0, l.x, right);
    set(1, l.y, false);
    set(2, l.z, right);
  }

  int revolute(const std::string& name, int parent, const Vector3& offset, const Vector3& axis_left, bool right,
               double lo_deg, double hi_deg) {
    const int j = model.addJoint(name, JointType::kRevolute, parent, at(offset), right ? mirrorAxis(axis_left) : axis_left);
    model.setLimits(model.joints[j].idx_q, lo_deg * kRadPerDeg, hi_deg * kRadPerDeg);
    return j;
  }
};

void checkSpec(const MannequinSpec& spec) {
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("mannequin '" + spec.name + "': " + what);
  };
  if (!std::isfinite(spec.stature) || spec.stature < 0.5 || spec.stature > 2.5)
    bad("stature " + std::to_string(spec.stature) + " m is outside [0.5, 2.5] m");
  if (!std::isfinite(spec.mass) || spec.mass < 10 || spec.mass > 300)
    bad("mass " + std::to_string(spec.mass) + " kg is outside [10, 300] kg");
  if (!std::isfinite(spec.density) || spec.density < 500 || spec.density > 2000)
    bad("density " + std::to_string(spec.density) + " kg/m^3 is outside [500, 2000]");
}
}  // namespace

Model buildMannequin(const MannequinSpec& spec) {
  checkSpec(spec);
  const Table& T = spec.sex == Sex::kMale ? kMale : kFemale;
  const double H = spec.stature;
  const double k = H / T.stature;  // scale of de Leva's lengths

  // lengths (m)
  const double ankle_h = kAnkleHeight * H;
  const double shank = T.shank.length * k, thigh = T.thigh.length * k;
  const double lpt = T.lower_trunk.length * k, mpt = T.mid_trunk.length * k, upt = T.upper_trunk.length * k;
  const double hip_h = ankle_h + shank + thigh;
  const double head = H - (hip_h + lpt + mpt + upt);  // suprasternale → vertex
  const double upper_arm = T.upper_arm.length * k, forearm = T.forearm.length * k, hand = T.hand.length * k;
  const double foot = T.foot.length * k;

  Model model;
  model.name = spec.name;
  Builder b{model, spec, spec.density};

  // trunk and head: pelvis (root) → lumbar → thoracic → neck, segments along +z
  const int root = model.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  {
    // the pelvis capsule lies across, between the hip joint centres
    b.segment("pelvis", root, T.lower_trunk, lpt, Vector3(0, 0, lpt), Vector3(0, 0, 0));
    Segment& pelvis = model.segments.back();
    const double w = kHipHalfWidth * H;
    pelvis.capsule.a = Vector3(0, w, 0.5 * lpt);
    pelvis.capsule.b = Vector3(0, -w, 0.5 * lpt);
    pelvis.capsule.radius = b.radiusFor(pelvis.mass, 2 * w + lpt);
  }
  const int lumbar = model.addJoint("lumbar", JointType::kBall, root, at({0, 0, lpt}));
  b.ballLimits(lumbar, kLumbar, false);
  b.segment("abdomen", lumbar, T.mid_trunk, mpt, Vector3(0, 0, mpt), Vector3(0, 0, 0));
  const int thoracic = model.addJoint("thoracic", JointType::kBall, lumbar, at({0, 0, mpt}));
  b.ballLimits(thoracic, kThoracic, false);
  b.segment("thorax", thoracic, T.upper_trunk, upt, Vector3(0, 0, upt), Vector3(0, 0, 0));
  const int neck = model.addJoint("neck", JointType::kBall, thoracic, at({0, 0, upt}));
  b.ballLimits(neck, kNeck, false);
  b.segment("head", neck, T.head, head, Vector3(0, 0, head), Vector3(0, 0, 0));
  model.addFrame("head_top", neck, at({0, 0, head}));

  for (bool right : {false, true}) {
    const std::string s = right ? "_r" : "_l";
    const auto side = [&](const Vector3& v) { return right ? mirror(v) : v; };

    // shoulder girdle: clavicle elevation at the suprasternale (massless; its mass is in the thorax)
    const int clav = b.revolute("sternoclavicular" + s, thoracic, Vector3(0, 0, upt), Vector3::UnitX(), right, -10, 30);
    const Vector3 sjc = side(Vector3(0, kShoulderHalfWidth * H, -kShoulderDrop * H));
    b.massless("clavicle" + s, clav, Vector3::Zero(), sjc, 0.03 * H / 1.75);

    // arm: shoulder (ball), elbow flexion, forearm pronation, wrist flexion and deviation
    const int shoulder = model.addJoint("shoulder" + s, JointType::kBall, clav, at(sjc));
    b.ballLimits(shoulder, kShoulder, right);
    b.segment("upper_arm" + s, shoulder, T.upper_arm, upper_arm, Vector3::Zero(), Vector3(0, 0, -upper_arm));
    const int elbow = b.revolute("elbow" + s, shoulder, Vector3(0, 0, -upper_arm), -Vector3::UnitY(), right, 0, 150);
    // pronation 80 + supination 80 around mid-position; zero here is full supination (palms forward)
    const int radioulnar = b.revolute("radioulnar" + s, elbow, Vector3::Zero(), -Vector3::UnitZ(), right, 0, 160);
    b.segment("forearm" + s, radioulnar, T.forearm, forearm, Vector3::Zero(), Vector3(0, 0, -forearm));
    const int wrist = b.revolute("wrist" + s, radioulnar, Vector3(0, 0, -forearm), -Vector3::UnitY(), right, -70, 80);
    const int wrist_dev = b.revolute("wrist_deviation" + s, wrist, Vector3::Zero(), Vector3::UnitX(), right, -30, 20);
    b.segment("hand" + s, wrist_dev, T.hand, hand, Vector3::Zero(), Vector3(0, 0, -hand));
    model.addFrame("palm" + s, wrist_dev, at({0.02 * H / 1.75, 0, -0.45 * hand}));

    // leg: hip (ball), knee flexion, ankle dorsiflexion and subtalar inversion
    const int hip = model.addJoint("hip" + s, JointType::kBall, root, at(side(Vector3(0, kHipHalfWidth * H, 0))));
    b.ballLimits(hip, kHip, right);
    b.segment("thigh" + s, hip, T.thigh, thigh, Vector3::Zero(), Vector3(0, 0, -thigh));
    const int knee = b.revolute("knee" + s, hip, Vector3(0, 0, -thigh), Vector3::UnitY(), right, 0, 135);
    b.segment("shank" + s, knee, T.shank, shank, Vector3::Zero(), Vector3(0, 0, -shank));
    const int ankle = b.revolute("ankle" + s, knee, Vector3(0, 0, -shank), -Vector3::UnitY(), right, -50, 20);
    const int subtalar = b.revolute("subtalar" + s, ankle, Vector3::Zero(), -Vector3::UnitX(), right, -15, 35);
    // the foot runs from the heel to the toe tip along x, its capsule resting on the sole
    const double foot_r = b.radiusFor(T.foot.mass * spec.mass, foot);
    const Vector3 heel(-kHeelToAnkle * foot, 0, -ankle_h + foot_r);
    const Vector3 toe(heel.x() + (spec.toes ? kToeJoint : 1.0) * foot, 0, heel.z());
    b.segment("foot" + s, subtalar, T.foot, foot, heel, Vector3(heel.x() + foot, 0, heel.z()), foot_r);
    model.segments.back().capsule.b = toe;
    model.addFrame("sole" + s, subtalar, at({heel.x() + 0.5 * foot, 0, -ankle_h}));
    if (spec.toes) {
      const int mtp = b.revolute("toes" + s, subtalar, toe, -Vector3::UnitY(), right, -45, 70);
      b.massless("toes" + s, mtp, Vector3::Zero(), Vector3((1.0 - kToeJoint) * foot, 0, 0), 0.8 * foot_r);
    }
  }

  // a frame at each segment's joint, named after the segment (control frames: pelvis, head, hand_l ...)
  for (const Segment& seg : std::vector<Segment>(model.segments))
    if (model.findFrame(seg.name) < 0) model.addFrame(seg.name, seg.joint, SE3::Identity());

  // overrides of joint limits, by coordinate name
  const auto names = model.coordinateNames();
  for (const auto& [coord, lim] : spec.limits_deg) {
    const auto it = std::find(names.begin(), names.end(), coord);
    if (it == names.end())
      throw std::invalid_argument("mannequin '" + spec.name + "': joint limit override for unknown coordinate '" +
                                  coord + "'");
    model.setLimits(static_cast<int>(it - names.begin()), lim.first * kRadPerDeg, lim.second * kRadPerDeg);
  }
  // swing/twist limits of every ball joint: from the boxes above, overridden by the spec
  for (const auto& [jname, deg] : spec.ball_limits_deg) {
    const int j = model.findJoint(jname);
    if (j < 0 || model.joints[j].type != JointType::kBall)
      throw std::invalid_argument("mannequin '" + spec.name + "': swing/twist limits for '" + jname +
                                  "', which is not a ball joint");
  }
  for (int j = 0; j < static_cast<int>(model.joints.size()); ++j) {
    if (model.joints[j].type != JointType::kBall) continue;
    const auto it = spec.ball_limits_deg.find(model.joints[j].name);
    model.setBallLimit(j, it == spec.ball_limits_deg.end() ? defaultBallLimit(model, j)
                                                           : ballLimitFromSpec(model, j, it->second));
  }
  return model;
}

BallLimit defaultBallLimit(const Model& model, int joint) {
  const Joint& jt = model.joints.at(joint);
  BallLimit l;
  l.twist_axis = -Vector3::UnitZ();
  for (const Segment& seg : model.segments)
    if (seg.joint == joint && seg.com.norm() > 1e-9) {
      l.twist_axis = seg.com.normalized();
      break;
    }
  swingBasis(l.twist_axis, l.swing_x, l.swing_y);
  // range of the box along a unit axis e: the component k with the largest |e_k|, signed
  const auto range = [&](const Vector3& e, double& lo, double& hi) {
    int k = 0;
    e.cwiseAbs().maxCoeff(&k);
    const double a = model.lower_limit(jt.idx_q + k), b = model.upper_limit(jt.idx_q + k);
    if (e(k) >= 0) {
      lo = a;
      hi = b;
    } else {
      lo = -b;
      hi = -a;
    }
    // an unlimited component: the largest range allowed
    lo = std::isfinite(lo) ? lo : -BallLimit::kMaxSwing;
    hi = std::isfinite(hi) ? hi : BallLimit::kMaxSwing;
  };
  double lx, hx, ly, hy;
  range(l.swing_x, lx, hx);
  range(l.swing_y, ly, hy);
  range(l.twist_axis, l.twist_lower, l.twist_upper);
  l.twist_lower = std::max(l.twist_lower, -BallLimit::kMaxTwist);
  l.twist_upper = std::min(l.twist_upper, BallLimit::kMaxTwist);
  l.swing_cx = 0.5 * (lx + hx);
  l.swing_cy = 0.5 * (ly + hy);
  const double a = 0.5 * (hx - lx), b = 0.5 * (hy - ly);
  l.swing_a = a;
  l.swing_b = b;
  const double m = l.maxSwing();
  if (m > BallLimit::kMaxSwing) {
    // shrink the ellipse about s = 0 (centre and semi-axes by the same factor): it keeps containing 0
    // and its farthest point comes to kMaxSwing
    const double k = (BallLimit::kMaxSwing - 1e-9) / m;
    l.swing_cx *= k;
    l.swing_cy *= k;
    l.swing_a *= k;
    l.swing_b *= k;
  }
  l.enabled = true;
  return l;
}

BallLimit ballLimitFromSpec(const Model& model, int joint, const MannequinSpec::BallLimitDeg& deg) {
  BallLimit l = defaultBallLimit(model, joint);
  if (deg.twist_axis) {
    l.twist_axis = deg.twist_axis->normalized();
    swingBasis(l.twist_axis, l.swing_x, l.swing_y);
  }
  if (deg.swing_axes) {
    l.swing_a = deg.swing_axes->first * kRadPerDeg;
    l.swing_b = deg.swing_axes->second * kRadPerDeg;
  }
  if (deg.swing_center) {
    l.swing_cx = deg.swing_center->first * kRadPerDeg;
    l.swing_cy = deg.swing_center->second * kRadPerDeg;
  }
  if (deg.twist) {
    l.twist_lower = deg.twist->first * kRadPerDeg;
    l.twist_upper = deg.twist->second * kRadPerDeg;
  }
  return l;
}

VectorX standingConfiguration(const Model& model) {
  VectorX q = model.neutralConfiguration();
  Data data(model);
  forwardKinematics(model, data, q);
  const int sole = model.findFrame("sole_l");
  const int root = 0;
  if (sole >= 0 && !model.joints.empty() && model.joints[root].type == JointType::kFreeFlyer)
    q(model.joints[root].idx_q + 2) = -data.oMf[sole].p.z();
  return q;
}

// ---- YAML config ------------------------------------------------------------------------
namespace {
MannequinSpec readMannequinSpec(const core::ConfigNode& root) {
  root.allowOnly({"name", "sex", "stature_m", "mass_kg", "toes", "density_kg_m3", "joint_limits_deg",
                  "ball_limits_deg", "description", "source"});
  MannequinSpec spec;
  spec.name = root.get("name", spec.name);
  spec.sex = root["sex"].choice({"male", "female"}) == 0 ? Sex::kMale : Sex::kFemale;
  spec.stature = root["stature_m"].numIn(0.5, 2.5);
  spec.mass = root["mass_kg"].numIn(10, 300);
  spec.toes = root.get("toes", spec.toes);
  spec.density = root.getIn("density_kg_m3", spec.density, 500, 2000);
  if (const auto limits = root.find("joint_limits_deg")) {
    // coordinate names are checked against the model built without the overrides (none read yet)
    const auto names = buildMannequin(spec).coordinateNames();
    for (const std::string& coord : limits->keys()) {
      const core::ConfigNode r = (*limits)[coord];
      if (std::find(names.begin(), names.end(), coord) == names.end())
        r.fail("unknown coordinate '" + coord + "' (see docs/mannequin-model.md, \"Joints\")");
      const Eigen::VectorXd lim = r.vector(2);
      if (lim(0) > lim(1)) r.fail("[min, max] in degrees with min > max");
      spec.limits_deg[coord] = {lim(0), lim(1)};
    }
  }
  if (const auto balls = root.find("ball_limits_deg")) {
    // joints are checked against the model with the box overrides (the defaults derive from them)
    const Model model = buildMannequin(spec);
    for (const std::string& jname : balls->keys()) {
      const core::ConfigNode e = (*balls)[jname];
      const int j = model.findJoint(jname);
      if (j < 0 || model.joints[j].type != JointType::kBall)
        e.fail("'" + jname + "' is not a ball joint (see docs/mannequin-model.md, \"Joints\")");
      e.allowOnly({"swing_axes", "swing_center", "twist", "twist_axis"});
      MannequinSpec::BallLimitDeg deg;
      const auto pair = [&](const char* key, std::optional<std::pair<double, double>>& out) {
        if (const auto n = e.find(key)) {
          const Eigen::VectorXd v = n->vector(2);
          out = std::pair<double, double>{v(0), v(1)};
        }
      };
      pair("swing_axes", deg.swing_axes);
      pair("swing_center", deg.swing_center);
      pair("twist", deg.twist);
      if (const auto n = e.find("twist_axis")) {
        const Vector3 t = n->vec3();
        if (t.norm() < 1e-9) n->fail("the twist axis must not be zero");
        deg.twist_axis = t.normalized();
      }
      const std::string err = checkBallLimit(ballLimitFromSpec(model, j, deg));
      if (!err.empty()) e.fail(err);
      spec.ball_limits_deg[jname] = deg;
    }
  }
  return spec;
}
}  // namespace

MannequinSpec parseMannequinSpec(const std::string& text, const std::string& source) {
  return readMannequinSpec(core::ConfigNode::parse(text, source));
}

MannequinSpec loadMannequinSpec(const std::string& path) { return readMannequinSpec(core::ConfigNode::load(path)); }

}  // namespace mannequin::skeleton
