#include "mannequin/skeleton/mjcf.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "mannequin/math/so3.hpp"
#include "mannequin/math/frame.hpp"

namespace mannequin::skeleton {

namespace {

std::string num(double x) {
  if (!std::isfinite(x)) throw std::invalid_argument("toMjcf: non-finite value in the model");
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", x);
  return buf;
}

std::string vec(const Vector3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

Eigen::Quaterniond quatOf(const Matrix3& R) {
  Eigen::Quaterniond qt(R);
  qt.normalize();
  if (qt.w() < 0) qt.coeffs() *= -1.0;
  return qt;
}

std::string quat(const Matrix3& R) {
  const Eigen::Quaterniond qt = quatOf(R);
  return num(qt.w()) + " " + num(qt.x()) + " " + num(qt.y()) + " " + num(qt.z());
}

using math::frameAlong;  // collision::CollisionWorld's and the MJCF export's frame of a capsule

std::string xmlName(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// The joints in the order of the bodies in the document (depth first, children in index order):
/// MuJoCo numbers its bodies, joints and qpos in this order.
std::vector<int> documentOrder(const Model& model) {
  std::vector<std::vector<int>> children(model.joints.size());
  std::vector<int> pending;
  for (std::size_t j = model.joints.size(); j-- > 0;) {
    const int p = model.joints[j].parent;
    if (p < 0) pending.push_back(static_cast<int>(j));
    else children[static_cast<std::size_t>(p)].push_back(static_cast<int>(j));
  }
  std::vector<int> order;
  while (!pending.empty()) {
    const int j = pending.back();
    pending.pop_back();
    order.push_back(j);
    const std::vector<int>& c = children[static_cast<std::size_t>(j)];  // in decreasing index order
    pending.insert(pending.end(), c.begin(), c.end());
  }
  return order;
}

struct Writer {
  const Model& model;
  const MjcfOptions& opt;
  std::vector<std::vector<int>> children;   // per joint
  std::vector<std::vector<int>> segments;   // per joint
  std::string out;

  void indent(int depth) { out.append(static_cast<std::size_t>(2 * depth), ' '); }

  void inertial(const Segment& s, int depth) {
    indent(depth);
    if (!(s.mass > 0.0)) {  // a massless segment (the clavicles): MuJoCo wants mass on every moving body
      out += "<inertial pos=\"" + vec(s.com) + "\" mass=\"" + num(opt.massless_mass) + "\" diaginertia=\"" +
             num(opt.massless_inertia) + " " + num(opt.massless_inertia) + " " + num(opt.massless_inertia) + "\"/>\n";
      return;
    }
    const Matrix3& I = s.inertia;
    out += "<inertial pos=\"" + vec(s.com) + "\" mass=\"" + num(s.mass) + "\" fullinertia=\"" + num(I(0, 0)) + " " +
           num(I(1, 1)) + " " + num(I(2, 2)) + " " + num(I(0, 1)) + " " + num(I(0, 2)) + " " + num(I(1, 2)) + "\"/>\n";
  }

  void geom(const Segment& s, int depth) {
    const Capsule& c = s.capsule;
    if (!(c.radius > 0.0)) return;
    const std::string contact = opt.self_collision ? " contype=\"1\" conaffinity=\"1\"" : " contype=\"1\" conaffinity=\"0\"";
    const std::string common = " name=\"" + xmlName(s.name) + "\"" + contact + " condim=\"3\" friction=\"" +
                               num(opt.friction) + " 0.005 0.0001\"";
    const Vector3 dir = c.b - c.a;
    const double len = dir.norm();
    indent(depth);
    if (opt.foot_boxes && s.name.rfind("foot", 0) == 0) {
      const Matrix3 R = len > 1e-12 ? frameAlong(dir) : Matrix3::Identity();
      out += "<geom" + common + " type=\"box\" size=\"" + num(c.radius) + " " + num(c.radius) + " " +
             num(0.5 * len + c.radius) + "\" pos=\"" + vec(0.5 * (c.a + c.b)) + "\" quat=\"" + quat(R) + "\"/>\n";
    } else if (len > 1e-12) {
      out += "<geom" + common + " type=\"capsule\" size=\"" + num(c.radius) + "\" fromto=\"" + vec(c.a) + " " +
             vec(c.b) + "\"/>\n";
    } else {
      out += "<geom" + common + " type=\"sphere\" size=\"" + num(c.radius) + "\" pos=\"" + vec(c.a) + "\"/>\n";
    }
  }

  void body(int j, int depth) {
    const Joint& J = model.joints[static_cast<std::size_t>(j)];
    indent(depth);
    out += "<body name=\"" + xmlName(J.name) + "\" pos=\"" + vec(J.placement.p) + "\" quat=\"" + quat(J.placement.R) + "\">\n";
    indent(depth + 1);
    switch (J.type) {
      case JointType::kFreeFlyer:
        out += "<freejoint name=\"" + xmlName(J.name) + "\"/>\n";
        break;
      case JointType::kRevolute: {
        out += "<joint name=\"" + xmlName(J.name) + "\" type=\"hinge\" axis=\"" + vec(J.axis) + "\"";
        const double lo = model.lower_limit[J.idx_q], hi = model.upper_limit[J.idx_q];
        if (std::isfinite(lo) && std::isfinite(hi)) out += " limited=\"true\" range=\"" + num(lo) + " " + num(hi) + "\"";
        out += "/>\n";
        break;
      }
      case JointType::kBall:
        out += "<joint name=\"" + xmlName(J.name) + "\" type=\"ball\"";
        if (J.ball_limit.enabled) out += " limited=\"true\" range=\"0 " + num(J.ball_limit.maxSwing()) + "\"";
        out += "/>\n";
        break;
    }
    const std::vector<int>& segs = segments[static_cast<std::size_t>(j)];
    if (segs.empty() && J.type != JointType::kFreeFlyer) {  // a joint without a segment: a moving body
      Segment none;
      inertial(none, depth + 1);
    }
    if (!segs.empty()) {
      inertial(model.segments[static_cast<std::size_t>(segs[0])], depth + 1);
      geom(model.segments[static_cast<std::size_t>(segs[0])], depth + 1);
    }
    for (std::size_t k = 1; k < segs.size(); ++k) {  // further segments: welded child bodies
      const Segment& s = model.segments[static_cast<std::size_t>(segs[k])];
      indent(depth + 1);
      out += "<body name=\"" + xmlName(s.name) + "\">\n";
      inertial(s, depth + 2);
      geom(s, depth + 2);
      indent(depth + 1);
      out += "</body>\n";
    }
    for (int c : children[static_cast<std::size_t>(j)]) body(c, depth + 1);
    indent(depth);
    out += "</body>\n";
  }
};

}  // namespace

std::string toMjcf(const Model& model, const MjcfOptions& options) {
  if (model.joints.empty()) throw std::invalid_argument("toMjcf: model '" + model.name + "' has no joint");
  if (!(options.timestep > 0.0) || !std::isfinite(options.timestep))
    throw std::invalid_argument("toMjcf: MjcfOptions.timestep must be finite and > 0");
  Writer w{model, options, {}, {}, {}};
  w.children.resize(model.joints.size());
  w.segments.resize(model.joints.size());
  std::vector<int> roots;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const int p = model.joints[j].parent;
    (p < 0 ? roots : w.children[static_cast<std::size_t>(p)]).push_back(static_cast<int>(j));
  }
  for (std::size_t s = 0; s < model.segments.size(); ++s)
    w.segments[static_cast<std::size_t>(model.segments[s].joint)].push_back(static_cast<int>(s));
  std::string& o = w.out;
  o += "<mujoco model=\"" + xmlName(model.name) + "\">\n";
  o += "  <!-- exported by mannequin (skeleton::toMjcf): " + std::to_string(model.joints.size()) + " joints, " +
       std::to_string(model.segments.size()) + " segments, total mass " + num(model.totalMass()) + " kg -->\n";
  o += "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n";
  o += "  <option timestep=\"" + num(options.timestep) + "\" gravity=\"" + vec(options.gravity) + "\"/>\n";
  if (options.nconmax > 0 || options.njmax > 0) {
    o += "  <size";
    if (options.nconmax > 0) o += " nconmax=\"" + std::to_string(options.nconmax) + "\"";
    if (options.njmax > 0) o += " njmax=\"" + std::to_string(options.njmax) + "\"";
    o += "/>\n";
  }
  o += "  <worldbody>\n";
  if (options.floor)
    o += "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" contype=\"1\" conaffinity=\"1\" condim=\"3\" friction=\"" +
         num(options.friction) + " 0.005 0.0001\"/>\n";
  for (int r : roots) w.body(r, 2);
  o += options.extra_worldbody;
  o += "  </worldbody>\n";
  o += "</mujoco>\n";
  return o;
}

std::vector<double> mjcfQpos(const Model& model, const VectorX& q) {
  if (q.size() != model.nq)
    throw std::invalid_argument("mjcfQpos: q has " + std::to_string(q.size()) + " coordinates, model '" + model.name +
                                "' has nq = " + std::to_string(model.nq));
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(model.nq) + 1 + model.joints.size());
  for (int j : documentOrder(model)) {
    const Joint& J = model.joints[static_cast<std::size_t>(j)];
    const double* x = q.data() + J.idx_q;
    switch (J.type) {
      case JointType::kFreeFlyer: {
        const SE3 H = J.placement * SE3(math::expSO3(Vector3(x[3], x[4], x[5])), Vector3(x[0], x[1], x[2]));
        const Eigen::Quaterniond qt = quatOf(H.R);
        out.insert(out.end(), {H.p.x(), H.p.y(), H.p.z(), qt.w(), qt.x(), qt.y(), qt.z()});
        break;
      }
      case JointType::kBall: {
        const Eigen::Quaterniond qt = quatOf(math::expSO3(Vector3(x[0], x[1], x[2])));
        out.insert(out.end(), {qt.w(), qt.x(), qt.y(), qt.z()});
        break;
      }
      case JointType::kRevolute:
        out.push_back(x[0]);
        break;
    }
  }
  return out;
}

}  // namespace mannequin::skeleton
