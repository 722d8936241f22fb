#include "mannequin/skeleton/kinematics.hpp"

#include <stdexcept>

#include "mannequin/core/check.hpp"

namespace mannequin::skeleton {

namespace {
// free-flyer coordinates (p, r) <-> pose
SE3 freeFlyerPose(const double* q) {
  return SE3(math::expSO3(Vector3(q[3], q[4], q[5])), Vector3(q[0], q[1], q[2]));
}
void setFreeFlyer(const SE3& H, double* q) {
  const Vector3 r = math::logSO3(H.R);
  for (int k = 0; k < 3; ++k) {
    q[k] = H.p(k);
    q[3 + k] = r(k);
  }
}
}  // namespace

SE3 jointTransform(const Joint& joint, const double* q) {
  switch (joint.type) {
    case JointType::kRevolute:
      return SE3(joint.placement.R * math::expSO3(joint.axis * q[0]), joint.placement.p);
    case JointType::kBall:
      return SE3(joint.placement.R * math::expSO3(Vector3(q[0], q[1], q[2])), joint.placement.p);
    case JointType::kFreeFlyer:
      return joint.placement * freeFlyerPose(q);
  }
  return joint.placement;
}

void forwardKinematics(const Model& model, Data& data, const VectorX& q) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q.size(), model.nq, "configuration q");
  // product of exponentials down the tree (1.14): oMi = oMparent · placement · exp(ξ q)
  for (size_t i = 0; i < model.joints.size(); ++i) {
    const Joint& j = model.joints[i];
    data.liMi[i] = jointTransform(j, q.data() + j.idx_q);
    data.oMi[i] = j.parent < 0 ? data.liMi[i] : data.oMi[j.parent] * data.liMi[i];
  }
  // frames ride on their joints
  for (size_t f = 0; f < model.frames.size(); ++f) {
    const Frame& fr = model.frames[f];
    data.oMf[f] = data.oMi[fr.joint] * fr.placement;
  }
}

const Matrix6X& computeJointJacobians(const Model& model, Data& data) {
  // column block of joint i = Ad_{oMi} S_i, S_i its motion subspace in the joint frame (1.22)
  for (size_t i = 0; i < model.joints.size(); ++i) {
    const Joint& j = model.joints[i];
    const SE3& H = data.oMi[i];
    switch (j.type) {
      case JointType::kRevolute: {
        const Vector3 w = H.R * j.axis;
        data.J.col(j.idx_v) << w, H.p.cross(w);
        break;
      }
      case JointType::kBall:
        for (int k = 0; k < 3; ++k) {
          const Vector3 w = H.R.col(k);
          data.J.col(j.idx_v + k) << w, H.p.cross(w);
        }
        break;
      case JointType::kFreeFlyer:
        data.J.middleCols<6>(j.idx_v) = math::Ad(H);
        break;
    }
  }
  return data.J;
}

const Matrix6X& computeJointJacobians(const Model& model, Data& data, const VectorX& q) {
  forwardKinematics(model, data, q);
  return computeJointJacobians(model, data);
}

namespace {
// world (spatial) Jacobian of joint `joint`: support columns copied, others zero
void supportColumns(const Model& model, const Data& data, int joint, Matrix6X& J) {
  if (J.cols() != model.nv) J.resize(6, model.nv);
  J.setZero();
  for (int k : model.support[joint]) {
    const Joint& jk = model.joints[k];
    J.middleCols(jk.idx_v, jk.nv) = data.J.middleCols(jk.idx_v, jk.nv);
  }
}

void changeReference(const SE3& oMf, ReferenceFrame rf, Matrix6X& J) {
  switch (rf) {
    case ReferenceFrame::kWorld:
      break;
    case ReferenceFrame::kLocal: {
      // body twist: Ad_{oMf}⁻¹ V_spatial, i.e. ω_b = Rᵀω, v_b = Rᵀ(v − p × ω)
      const Matrix3 Rt = oMf.R.transpose();
      for (Eigen::Index c = 0; c < J.cols(); ++c) {
        const Vector3 w = J.col(c).head<3>();
        const Vector3 v = J.col(c).tail<3>() - oMf.p.cross(w);
        J.col(c) << Rt * w, Rt * v;
      }
      break;
    }
    case ReferenceFrame::kLocalWorldAligned:
      // velocity of the frame origin: v + ω × p = v − p × ω
      for (Eigen::Index c = 0; c < J.cols(); ++c) {
        const Vector3 w = J.col(c).head<3>();
        J.col(c).tail<3>() -= oMf.p.cross(w);
      }
      break;
  }
}
}  // namespace

void frameJacobian(const Model& model, const Data& data, int frame, ReferenceFrame rf, Matrix6X& J) {
  if (frame < 0 || frame >= static_cast<int>(model.frames.size()))
    throw std::invalid_argument("frameJacobian: frame index " + std::to_string(frame) + " does not exist");
  supportColumns(model, data, model.frames[frame].joint, J);
  changeReference(data.oMf[frame], rf, J);
}

void jointJacobian(const Model& model, const Data& data, int joint, ReferenceFrame rf, Matrix6X& J) {
  if (joint < 0 || joint >= static_cast<int>(model.joints.size()))
    throw std::invalid_argument("jointJacobian: joint index " + std::to_string(joint) + " does not exist");
  supportColumns(model, data, joint, J);
  changeReference(data.oMi[joint], rf, J);
}

void pointJacobian(const Model& model, const Data& data, int joint, const Vector3& point, Matrix3X& J) {
  if (joint < 0 || joint >= static_cast<int>(model.joints.size()))
    throw std::invalid_argument("pointJacobian: joint index " + std::to_string(joint) + " does not exist");
  if (J.cols() != model.nv) J.resize(3, model.nv);
  J.setZero();
  const Vector3 x = data.oMi[joint].act(point);
  // v_A = v + ω × x for each supporting column (3.33–3.34)
  for (int k : model.support[joint]) {
    const Joint& jk = model.joints[k];
    for (int c = jk.idx_v; c < jk.idx_v + jk.nv; ++c) {
      J.col(c) = data.J.col(c).tail<3>() + data.J.col(c).head<3>().cross(x);
    }
  }
}

const Vector3& centerOfMass(const Model& model, Data& data) {
  Vector3 moment = Vector3::Zero();
  double mass = 0;
  for (size_t s = 0; s < model.segments.size(); ++s) {
    const Segment& seg = model.segments[s];
    data.segment_com[s] = data.oMi[seg.joint].act(seg.com);
    moment += seg.mass * data.segment_com[s];
    mass += seg.mass;
  }
  data.com = mass > 0 ? Vector3(moment / mass) : Vector3::Zero();
  return data.com;
}

const Matrix3X& jacobianCenterOfMass(const Model& model, Data& data) {
  centerOfMass(model, data);
  const size_t nj = model.joints.size();
  // subtree mass and first moment Σ m c, accumulated from the leaves (children follow parents)
  for (size_t i = 0; i < nj; ++i) {
    data.subtree_mass[i] = 0;
    data.subtree_moment[i].setZero();
  }
  double total = 0;
  for (size_t s = 0; s < model.segments.size(); ++s) {
    const Segment& seg = model.segments[s];
    data.subtree_mass[seg.joint] += seg.mass;
    data.subtree_moment[seg.joint] += seg.mass * data.segment_com[s];
    total += seg.mass;
  }
  for (size_t i = nj; i-- > 0;) {
    const int p = model.joints[i].parent;
    if (p >= 0) {
      data.subtree_mass[p] += data.subtree_mass[i];
      data.subtree_moment[p] += data.subtree_moment[i];
    }
  }
  if (total <= 0) {
    data.Jcom.setZero();
    return data.Jcom;
  }
  // column k of joint j moves its whole subtree: Σ m (v_k + ω_k × c) = M_sub v_k + ω_k × (Σ m c)
  for (size_t i = 0; i < nj; ++i) {
    const Joint& j = model.joints[i];
    for (int c = j.idx_v; c < j.idx_v + j.nv; ++c) {
      data.Jcom.col(c) = (data.subtree_mass[i] * data.J.col(c).tail<3>() +
                          data.J.col(c).head<3>().cross(data.subtree_moment[i])) / total;
    }
  }
  return data.Jcom;
}

VectorX integrate(const Model& model, const VectorX& q, const VectorX& v, double dt) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q.size(), model.nq, "configuration q");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(v.size(), model.nv, "velocity v");
  VectorX out = q;
  for (const Joint& j : model.joints) {
    switch (j.type) {
      case JointType::kRevolute:
        out(j.idx_q) = q(j.idx_q) + v(j.idx_v) * dt;
        break;
      case JointType::kBall: {
        const Matrix3 R = math::expSO3(q.segment<3>(j.idx_q)) * math::expSO3(v.segment<3>(j.idx_v) * dt);
        out.segment<3>(j.idx_q) = math::logSO3(R);
        break;
      }
      case JointType::kFreeFlyer: {
        const Vector6 V = v.segment<6>(j.idx_v) * dt;
        setFreeFlyer(freeFlyerPose(q.data() + j.idx_q) * math::expSE3(V), out.data() + j.idx_q);
        break;
      }
    }
  }
  return out;
}

VectorX difference(const Model& model, const VectorX& q0, const VectorX& q1) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q0.size(), model.nq, "configuration q0");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q1.size(), model.nq, "configuration q1");
  VectorX v(model.nv);
  for (const Joint& j : model.joints) {
    switch (j.type) {
      case JointType::kRevolute:
        v(j.idx_v) = q1(j.idx_q) - q0(j.idx_q);
        break;
      case JointType::kBall:
        v.segment<3>(j.idx_v) = math::logSO3(math::expSO3(q0.segment<3>(j.idx_q)).transpose() *
                                             math::expSO3(q1.segment<3>(j.idx_q)));
        break;
      case JointType::kFreeFlyer:
        v.segment<6>(j.idx_v) =
            math::logSE3(freeFlyerPose(q0.data() + j.idx_q).inverse() * freeFlyerPose(q1.data() + j.idx_q));
        break;
    }
  }
  return v;
}

VectorX clampToLimits(const Model& model, const VectorX& q) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q.size(), model.nq, "configuration q");
  return q.cwiseMax(model.lower_limit).cwiseMin(model.upper_limit);
}

}  // namespace mannequin::skeleton
