#pragma once
/// \file kinematics.hpp
/// \brief Forward kinematics by product of exponentials (thesis 1.14), joint/frame/point
/// Jacobians (1.22, 3.33–3.34), centre of mass and its Jacobian (3.28, 3.32–3.36), and the
/// configuration-space operations integrate/difference (Lie-group Euler, Annex C).
///
/// Frames of a 6×nv Jacobian J, with twists ordered (ω, v):
/// - kWorld: V = J v is the spatial twist V_{f/0(0)}, reduced at the WORLD ORIGIN, world axes;
/// - kLocal: the body twist V_{f/0(f)}, reduced at the frame origin, frame axes;
/// - kLocalWorldAligned: reduced at the frame origin, WORLD axes (v = velocity of that origin).
/// Columns of joints that do not move the frame are zero.
#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

enum class ReferenceFrame { kWorld, kLocal, kLocalWorldAligned };

/// Pose of every joint and frame for configuration q. Results in data.liMi, data.oMi, data.oMf.
/// \param[in] q (model.nq). \throws std::invalid_argument on a size mismatch.
void forwardKinematics(const Model& model, Data& data, const VectorX& q);

/// All joint Jacobian columns in the world frame. Result in data.J (6 × nv).
/// \pre forwardKinematics was called with the same q.
const Matrix6X& computeJointJacobians(const Model& model, Data& data);
/// Runs forwardKinematics first.
const Matrix6X& computeJointJacobians(const Model& model, Data& data, const VectorX& q);

/// 6 × nv Jacobian of a frame (see the file comment for the three reference frames).
/// \pre computeJointJacobians was called. \param[out] J resized to 6 × nv if needed.
void frameJacobian(const Model& model, const Data& data, int frame, ReferenceFrame rf, Matrix6X& J);

/// 6 × nv Jacobian of a joint frame (same conventions as frameJacobian).
void jointJacobian(const Model& model, const Data& data, int joint, ReferenceFrame rf, Matrix6X& J);

/// 3 × nv Jacobian of the world velocity of a point fixed in a joint frame (thesis 3.33–3.34:
/// J^r = [0 I] J_{A∈i/0(0)} reduced at A). \param[in] point in the joint frame (m).
/// \pre computeJointJacobians was called. \param[out] J resized to 3 × nv if needed.
void pointJacobian(const Model& model, const Data& data, int joint, const Vector3& point, Matrix3X& J);

/// Centre of mass of the whole body (3.28). Result in data.com (and data.segment_com).
/// \pre forwardKinematics was called.
const Vector3& centerOfMass(const Model& model, Data& data);

/// CoM Jacobian J_com = Σ m_i J_{com_i} / Σ m_i (3.32–3.36), world frame, computed in O(nv)
/// from subtree masses and first moments. Result in data.Jcom (3 × nv); also fills data.com.
/// \pre computeJointJacobians was called.
const Matrix3X& jacobianCenterOfMass(const Model& model, Data& data);

/// q ⊕ v·dt: explicit Euler on the configuration manifold (Annex C, Crouch–Grossman order 1):
/// revolute q + v dt; ball log(exp(q) exp(v dt)); free flyer H exp(V dt) with V the body twist.
/// \throws std::invalid_argument on size mismatch.
VectorX integrate(const Model& model, const VectorX& q, const VectorX& v, double dt = 1.0);

/// The inverse of integrate for dt = 1: the v with integrate(q0, v) = q1 (per joint log of the
/// relative transform; ball/free-flyer relative rotations must be below π).
VectorX difference(const Model& model, const VectorX& q0, const VectorX& q1);

/// Pose of a joint's local transform for its coordinates (the factor exp(ξ q) of 1.14 times the
/// placement). Exposed for tests and tools.
SE3 jointTransform(const Joint& joint, const double* q);

/// Clamps q into [model.lower_limit, model.upper_limit] (coordinates without limits untouched).
VectorX clampToLimits(const Model& model, const VectorX& q);

}  // namespace mannequin::skeleton
