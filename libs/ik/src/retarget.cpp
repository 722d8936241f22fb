#include "mannequin/ik/retarget.hpp"

#include <stdexcept>

namespace mannequin::ik {

const std::vector<std::string>& Retargeter::controlledSegments() {
  static const std::vector<std::string> names{"foot_l", "foot_r", "pelvis", "hand_l", "hand_r", "head"};
  return names;
}

Retargeter::Retargeter(const Model& model, const skeleton::Bvh& bvh, const skeleton::BvhDriveMap& map,
                       RetargetOptions options)
    : bvh_(bvh), driver_(model, bvh, map), options_(std::move(options)) {
  if (options_.calibration != "first" && options_.calibration != "rest")
    throw std::invalid_argument("retarget: calibration must be 'first' or 'rest', got '" + options_.calibration + "'");
  if (options_.max_iterations < 1) throw std::invalid_argument("retarget: max_iterations must be >= 1");
  length_scale_ = map.unit_scale_to_m;
  A_ << 0, 0, 1,
        1, 0, 0,
        0, 1, 0;  // BVH world (y up, facing +z) → mannequin world (z up, facing +x), as BvhDriver
  for (const auto& seg : controlledSegments()) {
    int b = -1;
    for (const auto& [s, j] : map.segments)
      if (s == seg) b = skeleton::findBvhJoint(bvh, j);
    if (b < 0)
      throw std::invalid_argument("retarget: mapping '" + map.name + "' does not drive segment '" + seg +
                                  "' (retargeting needs pelvis, foot_l/r, hand_l/r, head)");
    bvh_joint_.push_back(b);
  }

  // calibration: actor poses and mannequin poses at the calibration pose
  std::vector<SE3> world(bvh.joints.size());
  VectorX q_c;
  if (options_.calibration == "first") {
    const int f = skeleton::resolveBvhFrame(bvh, options_.calibration_frame);
    skeleton::bvhForwardKinematics(bvh, skeleton::bvhFrame(bvh, f), world, length_scale_);
    q_c = driver_.drive(f).q;
  } else {
    const std::vector<double> zeros(static_cast<std::size_t>(bvh.num_channels), 0.0);
    skeleton::bvhForwardKinematics(bvh, zeros, world, length_scale_);
    q_c = model.neutralConfiguration();
    q_c.head<3>() = driver_.scale() * (A_ * world[bvh_joint_[2]].p);
  }
  Data data(model);
  skeleton::forwardKinematics(model, data, q_c);
  for (std::size_t i = 0; i < controlledSegments().size(); ++i) {
    const SE3 M = data.oMf[model.frameIndex(controlledSegments()[i])];
    offset_.push_back(actorPose(world, static_cast<int>(i)).inverse() * M);
  }

  SolverOptions so;
  so.max_iterations = options_.max_iterations;
  solver_ = std::make_unique<IkSolver>(model, so);
  const int feet = solver_->addLevel({"feet", 0.01, options_.feet_tolerance});
  const int pelvis = solver_->addLevel({"pelvis", 0.01, options_.pelvis_tolerance});
  const int hands = solver_->addLevel({"hands", 0.02, options_.hands_tolerance});
  const int last = solver_->addLevel({"head+posture", 0.05, std::numeric_limits<double>::infinity()});
  const int level_of[] = {feet, feet, pelvis, hands, hands};
  for (int i = 0; i < 5; ++i)
    tasks_.push_back(&solver_->emplaceTask<FrameTask>(level_of[i], model, controlledSegments()[i]));
  tasks_.push_back(&solver_->emplaceTask<FrameTask>(last, model, "head", "", "xyz"));
  VectorX w = VectorX::Constant(model.nv, 0.1);  // posture: a weak attraction (cost level)
  posture_ = &solver_->emplaceTask<PostureTask>(last, model, q_c, PostureTask::Form::kJointSpace, w);
  q_ = q_c;
}

SE3 Retargeter::actorPose(const std::vector<SE3>& world, int i) const {
  const SE3& W = world[bvh_joint_[i]];
  return SE3(A_ * W.R * A_.transpose(), A_ * W.p);
}

RetargetFrame Retargeter::solve(long long frame) {
  const int f = skeleton::resolveBvhFrame(bvh_, frame);
  std::vector<SE3> world(bvh_.joints.size());
  skeleton::bvhForwardKinematics(bvh_, skeleton::bvhFrame(bvh_, f), world, length_scale_);
  for (std::size_t i = 0; i < tasks_.size(); ++i) tasks_[i]->setTarget(actorPose(world, static_cast<int>(i)) * offset_[i]);
  const VectorX transfer = driver_.drive(f).q;
  posture_->setReference(transfer);
  if (!warm_ || !options_.warm_start) {
    q_ = transfer;  // start from the orientation transfer of this frame
    warm_ = true;
  }
  RetargetFrame out;
  out.report = solver_->solve(q_);
  out.q = q_;
  return out;
}

}  // namespace mannequin::ik
