#include "mannequin/control/first_order.hpp"

#include <stdexcept>

#include "mannequin/core/check.hpp"

namespace mannequin::control {

namespace {
SE3 freeFlyerPose(const double* q) { return SE3(math::expSO3(Vector3(q[3], q[4], q[5])), Vector3(q[0], q[1], q[2])); }
}  // namespace

void integrateInPlace(const skeleton::Model& model, const VectorX& q, const VectorX& v, double dt, VectorX& q_out) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q.size(), model.nq, "configuration q");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(v.size(), model.nv, "velocity v");
  if (q_out.size() != model.nq) q_out.resize(model.nq);
  for (const skeleton::Joint& j : model.joints) {
    switch (j.type) {
      case skeleton::JointType::kRevolute:
        q_out(j.idx_q) = q(j.idx_q) + v(j.idx_v) * dt;
        break;
      case skeleton::JointType::kBall: {
        // body angular velocity: R ← R exp(ω δt)
        const Matrix3 R = math::expSO3(q.segment<3>(j.idx_q)) * math::expSO3(v.segment<3>(j.idx_v) * dt);
        q_out.segment<3>(j.idx_q) = math::logSO3(R);
        break;
      }
      case skeleton::JointType::kFreeFlyer: {
        // body twist: H ← H exp(V δt) (Crouch–Grossman order 1 on SE(3))
        const Vector6 V = v.segment<6>(j.idx_v) * dt;
        const SE3 H = freeFlyerPose(q.data() + j.idx_q) * math::expSE3(V);
        q_out.segment<3>(j.idx_q) = H.p;
        q_out.segment<3>(j.idx_q + 3) = math::logSO3(H.R);
        break;
      }
    }
  }
}

void differenceInPlace(const skeleton::Model& model, const VectorX& q0, const VectorX& q1, VectorX& v_out) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q0.size(), model.nq, "configuration q0");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q1.size(), model.nq, "configuration q1");
  if (v_out.size() != model.nv) v_out.resize(model.nv);
  for (const skeleton::Joint& j : model.joints) {
    switch (j.type) {
      case skeleton::JointType::kRevolute:
        v_out(j.idx_v) = q1(j.idx_q) - q0(j.idx_q);
        break;
      case skeleton::JointType::kBall:
        v_out.segment<3>(j.idx_v) =
            math::logSO3(math::expSO3(q0.segment<3>(j.idx_q)).transpose() * math::expSO3(q1.segment<3>(j.idx_q)));
        break;
      case skeleton::JointType::kFreeFlyer:
        v_out.segment<6>(j.idx_v) =
            math::logSE3(freeFlyerPose(q0.data() + j.idx_q).inverse() * freeFlyerPose(q1.data() + j.idx_q));
        break;
    }
  }
}

}  // namespace mannequin::control
