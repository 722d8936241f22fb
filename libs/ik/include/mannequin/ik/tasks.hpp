#pragma once
/// \file tasks.hpp
/// \brief Tasks of the priority IK: what each level asks of the mannequin (paper 2.3).
///
/// A task gives, at the current configuration, its Jacobian J (dim × nv) in IK COORDINATES and
/// its error e (dim), the variation Δx it asks for (e ≈ J Δθ cancels it to first order).
///
/// IK coordinates Δθ (nv, same layout as the skeleton's velocity v):
/// - revolute: the angle (rad), as in q;
/// - ball: the rotation vector itself (the three q coordinates), so joint limits written on the
///   rotation vector clamp exactly; a velocity-space column block J_v maps as J_v Jr(q);
/// - free flyer (root): the body twist (ω, v) of the root, applied by exp on SE(3).
/// IkContext::fromVelocity converts a velocity-space Jacobian (skeleton/kinematics.hpp).
///
/// Errors are in the WORLD frame: position p_d − p (m); orientation log(R_d Rᵀ) (rad, the world
/// angular displacement that takes R onto R_d), matching the rows of the LocalWorldAligned Jacobian.
#include <limits>
#include <memory>
#include <string>

#include "mannequin/math/se3.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::ik {

using math::Matrix3;
using math::MatrixX;
using math::SE3;
using math::Vector3;
using math::VectorX;
using skeleton::Data;
using skeleton::Model;

/// What a task sees: the model, the kinematic buffers at q (FK, joint Jacobians and, when a task
/// needs it, the CoM Jacobian are computed), and the conversion to IK coordinates.
class IkContext {
 public:
  IkContext(const Model& model, Data& data) : model_(model), data_(data) {}
  const Model& model() const { return model_; }
  const Data& data() const { return data_; }
  const VectorX& q() const { return *q_; }
  /// Velocity-space Jacobian (rows × nv) → IK coordinates (ball blocks times Jr(q)), in place.
  void fromVelocity(Eigen::Ref<MatrixX> J) const;
  void setConfiguration(const VectorX& q) { q_ = &q; }

 private:
  const Model& model_;
  Data& data_;
  const VectorX* q_ = nullptr;
};

/// Largest error one convergence-loop iteration asks (the linearisation's validity, paper Fig. 6).
struct StepLimits {
  double linear = 0.05;   ///< m
  double angular = 0.2;   ///< rad
  /// Largest change of one coordinate per level and iteration (rad, or m/rad for the root twist):
  /// a larger level contribution is scaled down (PriorityOptions::max_step, the priorities are
  /// kept). Keeps joints from jumping onto their limits far from the linearisation point.
  double joint = std::numeric_limits<double>::infinity();
};

class Task {
 public:
  explicit Task(std::string name) : name_(std::move(name)) {}
  virtual ~Task() = default;
  const std::string& name() const { return name_; }
  /// Number of rows.
  virtual int dim() const = 0;
  /// Whether evaluate() reads the CoM Jacobian (data.Jcom).
  virtual bool needsCom() const { return false; }
  /// J (dim × nv, IK coordinates) and e (dim) at ctx.q().
  virtual void evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const = 0;
  /// Scales e into one iteration's reach (convergence loop). Default: none.
  virtual void limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const;
  /// Norm used for the reports (default ‖e‖).
  virtual double residual(Eigen::Ref<const VectorX> e) const { return e.norm(); }

  /// Weight inside its level: rows scaled by √weight (weighted least squares within a level).
  double weight() const { return weight_; }
  void setWeight(double w);

 private:
  std::string name_;
  double weight_ = 1.0;
};

/// Axis selection "xyz", "xy", "z", "" … (world axes) → a bit mask.
unsigned parseAxes(const std::string& axes, const std::string& what);

/// Position and/or orientation of a frame (or of a point fixed in it) in the world.
/// Rows: the selected world angular axes first, then the selected world position axes.
class FrameTask : public Task {
 public:
  /// \param frame a frame name of the model. \param position_axes / orientation_axes subsets of
  /// "xyz" (world axes). \param point a point in the frame (m) whose position is controlled.
  /// \throws std::invalid_argument on an unknown frame (listing the frames) or bad axes.
  FrameTask(const Model& model, const std::string& frame, const std::string& position_axes = "xyz",
            const std::string& orientation_axes = "xyz", const Vector3& point = Vector3::Zero(),
            std::string name = {});
  int dim() const override { return dim_; }
  void evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const override;
  void limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const override;

  /// Target pose of the frame (the point's target is target.act(point)).
  /// \throws std::invalid_argument (naming the task) on a non-finite or non-rotation target; the
  /// previous target is kept.
  void setTarget(const SE3& target);
  /// Target position of the point only (orientation target kept).
  void setTargetPosition(const Vector3& p);
  const SE3& target() const { return target_; }
  int frame() const { return frame_; }
  /// Current pose of the frame (from the context's data).
  SE3 current(const IkContext& ctx) const;

 private:
  int frame_;
  Vector3 point_;
  unsigned pos_mask_, rot_mask_;
  int npos_, nrot_, dim_;
  SE3 target_;
  mutable math::Matrix6X J6_;
};

/// Centre of mass position (e.g. "xy": on the vertical line through the target; "z": on a
/// horizontal plane). World frame.
class ComTask : public Task {
 public:
  explicit ComTask(const std::string& axes = "xy", std::string name = "com");
  int dim() const override { return dim_; }
  bool needsCom() const override { return true; }
  void evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const override;
  void limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const override;
  /// \throws std::invalid_argument on a non-finite target (previous target kept).
  void setTarget(const Vector3& c);
  const Vector3& target() const { return target_; }

 private:
  unsigned mask_;
  int dim_;
  Vector3 target_ = Vector3::Zero();
};

/// Attraction to a reference posture (a cost-function level, paper eq. 5), on the internal
/// coordinates (the root is never attracted). Two forms:
/// - kJointSpace: one row per attracted coordinate, e = √w_i (q_ref,i − q_i) (all joints pulled);
/// - kCostGradient: one row, g(θ) = ½ Σ w_i (q_i − q_ref,i)², J = ∇gᵀ, e = −β g (eq. 5).
class PostureTask : public Task {
 public:
  enum class Form { kJointSpace, kCostGradient };
  /// \param weights (nv) per-coordinate weights ≥ 0; root entries are ignored. Empty = all 1.
  /// \throws std::invalid_argument on sizes, negative/NaN weights, β outside (0, 1].
  PostureTask(const Model& model, const VectorX& reference, Form form = Form::kJointSpace,
              const VectorX& weights = {}, double beta = 0.1, std::string name = "posture");
  int dim() const override { return dim_; }
  void evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const override;
  void limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const override;
  double residual(Eigen::Ref<const VectorX> e) const override;
  /// \throws std::invalid_argument on a wrong size or non-finite entry (previous reference kept).
  void setReference(const VectorX& q_ref);
  const VectorX& reference() const { return ref_; }
  Form form() const { return form_; }

 private:
  Form form_;
  VectorX ref_, w_;
  std::vector<int> coords_;  ///< attracted coordinates (IK = q indices, root excluded, w > 0)
  int dim_;
  double beta_;
};

}  // namespace mannequin::ik
