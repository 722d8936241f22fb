#include "mannequin/skeleton/dynamics.hpp"

#include <stdexcept>
#include <string>

#include "mannequin/core/check.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::skeleton {

namespace {

// spatial motion cross product V × M, (ω, v) order
Vector6 crossMotion(const Vector6& V, const Vector6& M) {
  Vector6 out;
  out.head<3>() = V.head<3>().cross(M.head<3>());
  out.tail<3>() = V.head<3>().cross(M.tail<3>()) + V.tail<3>().cross(M.head<3>());
  return out;
}

// spatial force cross product V ×* F, F = (n, f)
Vector6 crossForce(const Vector6& V, const Vector6& F) {
  Vector6 out;
  out.head<3>() = V.head<3>().cross(F.head<3>()) + V.tail<3>().cross(F.tail<3>());
  out.tail<3>() = V.head<3>().cross(F.tail<3>());
  return out;
}

// The spatial inertia of one segment (mass m, CoM c and inertia I_c about it, world) applied to a
// spatial motion X reduced at the origin: h = (I_c ω + c × m v_c, m v_c), v_c = v + ω × c the
// velocity of the point at c.
Vector6 inertiaTimes(double m, const Vector3& c, const Matrix3& Ic, const Vector6& X) {
  const Vector3 p = m * (X.tail<3>() + X.head<3>().cross(c));
  Vector6 h;
  h.head<3>() = Ic * X.head<3>() + c.cross(p);
  h.tail<3>() = p;
  return h;
}

}  // namespace

const VectorX& rnea(const Model& model, Data& data, const VectorX& q, const VectorX& v, const VectorX& a,
                    const Vector3& gravity, const std::vector<Vector6>* fext) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(v.size(), model.nv, "velocity v");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(a.size(), model.nv, "acceleration a");
  if (fext) MANNEQUIN_CHECK_ARGUMENT_SIZE(static_cast<Eigen::Index>(fext->size()), static_cast<Eigen::Index>(model.joints.size()),
                      "external wrenches fext");
  computeJointJacobians(model, data, q);
  const size_t nj = model.joints.size();
  // forward pass: twists and spatial accelerations; gravity enters as an upward acceleration of the
  // world (Featherstone's a_0 = −a_g), so every joint wrench below includes the weight
  Vector6 a_world;
  a_world << Vector3::Zero(), -gravity;
  for (size_t i = 0; i < nj; ++i) {
    const Joint& j = model.joints[i];
    const auto S = data.J.middleCols(j.idx_v, j.nv);
    const Vector6 vJ = S * v.segment(j.idx_v, j.nv);
    const Vector6& V_parent = j.parent < 0 ? Vector6::Zero().eval() : data.joint_twist[j.parent];
    const Vector6& A_parent = j.parent < 0 ? a_world : data.joint_accel[j.parent];
    data.joint_twist[i] = V_parent + vJ;
    // the joint's columns are fixed in its child: dS/dt = V_i × S
    data.joint_accel[i] = A_parent + S * a.segment(j.idx_v, j.nv) + crossMotion(data.joint_twist[i], vJ);
    data.joint_wrench[i] = fext ? Vector6(-(*fext)[i]) : Vector6::Zero();
  }
  // each segment's inertial wrench I A + V ×* I V on the joint carrying it
  for (const Segment& seg : model.segments) {
    const SE3& H = data.oMi[seg.joint];
    const Vector3 c = H.act(seg.com);
    const Matrix3 Ic = H.R * seg.inertia * H.R.transpose();
    const Vector6& V = data.joint_twist[seg.joint];
    data.joint_wrench[seg.joint] +=
        inertiaTimes(seg.mass, c, Ic, data.joint_accel[seg.joint]) + crossForce(V, inertiaTimes(seg.mass, c, Ic, V));
  }
  // backward pass: each joint carries its subtree's wrench; τ_i = S_iᵀ f_i
  for (size_t k = nj; k-- > 0;) {
    const Joint& j = model.joints[k];
    data.tau.segment(j.idx_v, j.nv) = data.J.middleCols(j.idx_v, j.nv).transpose() * data.joint_wrench[k];
    if (j.parent >= 0) data.joint_wrench[j.parent] += data.joint_wrench[k];
  }
  return data.tau;
}

double kineticEnergy(const Model& model, Data& data, const VectorX& q, const VectorX& v) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(v.size(), model.nv, "velocity v");
  computeJointJacobians(model, data, q);
  for (size_t i = 0; i < model.joints.size(); ++i) {
    const Joint& j = model.joints[i];
    const Vector6 vJ = data.J.middleCols(j.idx_v, j.nv) * v.segment(j.idx_v, j.nv);
    data.joint_twist[i] = j.parent < 0 ? vJ : Vector6(data.joint_twist[j.parent] + vJ);
  }
  double T = 0;
  for (const Segment& seg : model.segments) {
    const SE3& H = data.oMi[seg.joint];
    const Vector3 c = H.act(seg.com);
    const Vector6& V = data.joint_twist[seg.joint];
    const Vector3 vc = V.tail<3>() + V.head<3>().cross(c);
    const Vector3 w_local = H.R.transpose() * V.head<3>();
    T += 0.5 * (seg.mass * vc.squaredNorm() + w_local.dot(seg.inertia * w_local));
  }
  return T;
}

Vector6 wrenchAt(const Vector3& point, const Vector3& force) {
  Vector6 w;
  w << point.cross(force), force;
  return w;
}

Vector3 momentAbout(const Vector6& wrench, const Vector3& point) {
  return wrench.head<3>() - point.cross(wrench.tail<3>());
}

}  // namespace mannequin::skeleton
