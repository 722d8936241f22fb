#pragma once
/// \file dynamics.hpp
/// \brief Inverse dynamics of the kinematic tree: the recursive Newton–Euler algorithm (RNEA,
/// Featherstone, "Rigid Body Dynamics Algorithms", 2008, §5.3, written in the world frame), the
/// kinetic energy and spatial-force helpers.
///
/// Conventions (those of kinematics.hpp): twists and accelerations are (ω, v) spatial vectors reduced
/// at the WORLD ORIGIN, world axes; wrenches are (n, f) — the moment about the world origin, then the
/// force — world axes, so that power = wrenchᵀ · twist. v and a are the model's velocity coordinates
/// and their time derivatives (ball joints: the child's angular velocity in its own frame; the free
/// flyer: the root's body twist), so τ is dual to v (τᵀv is a power, N·m/s).
///
/// The equation of motion of the tree with external wrenches f_ext,i on its joints' bodies:
///   M(q) a + C(q, v) v + g(q) = τ + Σ_i J_iᵀ f_ext,i
/// rnea() returns τ given (q, v, a). For a free-flyer root, τ's first six entries are the body-frame
/// wrench that something outside the joints must apply to the root for the motion to happen — zero
/// for a motion that contacts and gravity alone can produce — and data.joint_wrench[0] is the same
/// wrench in the world frame: the whole body's rate of momentum minus its weight minus the external
/// wrenches.
#include <vector>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

/// Inverse dynamics τ = M(q) a + C(q, v) v + g(q) − Σ J_iᵀ f_ext,i (RNEA, O(n)).
/// \param[in] gravity the acceleration of gravity, world (m/s², e.g. (0, 0, −9.81)).
/// \param[in] fext optional, one wrench per joint (model.joints.size()): the external wrench applied
///   to the segments carried by that joint, world frame, moment about the world origin (see
///   wrenchAt()). nullptr: none.
/// Results: data.tau (nv); data.joint_wrench[i], the wrench the parent applies to the subtree of
/// joint i through joint i (world, about the origin); data.joint_twist[i] and data.joint_accel[i]
/// (spatial, world, at the origin); forward kinematics and data.J for q.
/// \throws std::invalid_argument on a size mismatch.
const VectorX& rnea(const Model& model, Data& data, const VectorX& q, const VectorX& v, const VectorX& a,
                    const Vector3& gravity, const std::vector<Vector6>* fext = nullptr);

/// Kinetic energy ½ Σ_segments (m |v_c|² + ωᵀ I_c ω) of the tree moving with velocity v (J).
/// Runs forward kinematics and the joint Jacobians for q.
double kineticEnergy(const Model& model, Data& data, const VectorX& q, const VectorX& v);

/// The spatial wrench (n, f) of a force `force` applied at `point` (world): n = point × force.
Vector6 wrenchAt(const Vector3& point, const Vector3& force);

/// The moment of a spatial wrench (moment about the world origin, force) about another point (world):
/// n_p = n − p × f.
Vector3 momentAbout(const Vector6& wrench, const Vector3& point);

}  // namespace mannequin::skeleton
