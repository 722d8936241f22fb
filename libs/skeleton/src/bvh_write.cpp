#include "mannequin/skeleton/bvh_write.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::skeleton {

Matrix3 mannequinToBvhAxes() {
  Matrix3 C;
  C << 0, 1, 0,
       0, 0, 1,
       1, 0, 0;
  return C;
}

namespace {

constexpr double kCm = 100.0;
constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// R = Rz(a) Rx(b) Ry(c) → (a, b, c) in degrees
Vector3 eulerZXY(const Matrix3& R) {
  const double sb = std::clamp(R(2, 1), -1.0, 1.0);
  const double b = std::asin(sb);
  double a, c;
  if (std::abs(sb) < 1.0 - 1e-12) {
    c = std::atan2(-R(2, 0), R(2, 2));
    a = std::atan2(-R(0, 1), R(1, 1));
  } else {  // gimbal lock: only a ± c is defined
    c = 0.0;
    a = std::atan2(R(1, 0), R(0, 0));
  }
  return Vector3(a, b, c) * kDegPerRad;
}

void indent(std::ostream& out, int depth) {
  for (int i = 0; i < depth; ++i) out << "  ";
}

void writeJoint(std::ostream& out, const Model& model, const std::vector<std::vector<int>>& children, int j, int depth,
                const Matrix3& C) {
  const Joint& J = model.joints[j];
  char buf[160];
  indent(out, depth);
  out << (J.parent < 0 ? "ROOT " : "JOINT ") << J.name << "\n";
  indent(out, depth);
  out << "{\n";
  const Vector3 off = J.parent < 0 ? Vector3::Zero() : Vector3(C * J.placement.p * kCm);
  indent(out, depth + 1);
  std::snprintf(buf, sizeof buf, "OFFSET %.6f %.6f %.6f\n", off.x(), off.y(), off.z());
  out << buf;
  indent(out, depth + 1);
  out << (J.parent < 0 ? "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                       : "CHANNELS 3 Zrotation Xrotation Yrotation\n");
  if (children[j].empty()) {
    Vector3 tip = Vector3::Zero();
    for (const auto& s : model.segments)
      if (s.joint == j) tip = s.capsule.b;
    if (tip.norm() < 1e-6) tip = Vector3(0, 0, 0.05);
    tip = C * tip * kCm;
    indent(out, depth + 1);
    out << "End Site\n";
    indent(out, depth + 1);
    out << "{\n";
    indent(out, depth + 2);
    std::snprintf(buf, sizeof buf, "OFFSET %.6f %.6f %.6f\n", tip.x(), tip.y(), tip.z());
    out << buf;
    indent(out, depth + 1);
    out << "}\n";
  }
  for (int c : children[j]) writeJoint(out, model, children, c, depth + 1, C);
  indent(out, depth);
  out << "}\n";
}

}  // namespace

void writeMannequinBvh(std::ostream& out, const Model& model, const std::vector<VectorX>& frames, double frame_time) {
  if (!(frame_time > 0.0) || !std::isfinite(frame_time))
    throw std::invalid_argument("BVH writer: frame time must be finite and > 0");
  if (model.joints.empty() || model.joints[0].parent >= 0) throw std::invalid_argument("BVH writer: model has no root");
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].size() != model.nq)
      throw std::invalid_argument("BVH writer: frame " + std::to_string(f) + " has " +
                                  std::to_string(frames[f].size()) + " coordinates, expected " + std::to_string(model.nq));
    if (!frames[f].allFinite()) throw std::invalid_argument("BVH writer: frame " + std::to_string(f) + " is not finite");
  }
  const Matrix3 C = mannequinToBvhAxes();
  std::vector<std::vector<int>> children(model.joints.size());
  for (std::size_t j = 1; j < model.joints.size(); ++j) children[model.joints[j].parent].push_back(static_cast<int>(j));
  out << "HIERARCHY\n";
  writeJoint(out, model, children, 0, 0, C);
  out << "MOTION\nFrames: " << frames.size() << "\n";
  char buf[64];
  std::snprintf(buf, sizeof buf, "Frame Time: %.8f\n", frame_time);
  out << buf;
  // channel order = depth-first order of the HIERARCHY
  std::vector<int> order;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const int j = stack.back();
    stack.pop_back();
    order.push_back(j);
    for (auto it = children[j].rbegin(); it != children[j].rend(); ++it) stack.push_back(*it);
  }
  for (const VectorX& q : frames) {
    std::string line;
    for (int j : order) {
      const Joint& J = model.joints[j];
      const SE3 L = jointTransform(J, q.data() + J.idx_q);
      if (J.parent < 0) {
        const Vector3 p = C * L.p * kCm;
        std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f ", p.x(), p.y(), p.z());
        line += buf;
      }
      const Vector3 e = eulerZXY(C * L.R * C.transpose());
      std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f ", e.x(), e.y(), e.z());
      line += buf;
    }
    line.back() = '\n';
    out << line;
  }
}

void writeMannequinBvhFile(const std::string& path, const Model& model, const std::vector<VectorX>& frames,
                           double frame_time) {
  const std::string tmp = path + ".tmp";
  try {
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
    writeMannequinBvh(f, model, frames, frame_time);
    f.flush();
    if (!f) throw std::runtime_error("write to '" + tmp + "' failed");
  } catch (...) {
    std::error_code ignore;
    std::filesystem::remove(tmp, ignore);
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
}

}  // namespace mannequin::skeleton
