#pragma once
/// \file retarget.hpp
/// \brief Kinematic retargeting of an actor's captured motion (BVH) onto a mannequin of another
/// size with the strict-priority IK (thesis 1.4.1, Fig. 1.9–1.10, 1.30, 2.12).
///
/// Per frame, from the frame's orientation transfer (or the previous solution, warm_start):
/// - the actor's segment poses G_s(t) come from the BVH (axes turned into the mannequin's world:
///   z up, x forward), unscaled: the Cartesian constraints (feet on the floor, hands on the
///   object) are kept in absolute space, constraint-oriented retargeting (Fig. 1.9 left);
/// - calibration (Fig. 1.10): at one calibration pose, the offsets O_s = G_s(c)⁻¹ M_s(c) between
///   the actor's segments and the mannequin's (posed by the orientation transfer BvhDriver) are
///   stored; the targets are then T_s(t) = G_s(t) O_s, so at the calibration frame every target
///   is met exactly whatever the sizes;
/// - levels, highest first: feet (6D), pelvis (6D), hands (6D), head orientation + posture
///   (attraction to the orientation transfer of the frame, i.e. the actor's attitude, Fig. 1.9
///   right). Feet and pelvis are both "top" in the thesis's sense but in two levels: for a
///   mannequin of another size they conflict, and the feet must win (otherwise the mannequin is
///   lifted off the floor, Fig. 2.12).
#include <memory>
#include <string>
#include <vector>

#include "mannequin/ik/solver.hpp"
#include "mannequin/skeleton/bvh.hpp"
#include "mannequin/skeleton/bvh_drive.hpp"

namespace mannequin::ik {

struct RetargetOptions {
  /// Calibration pose: "first" (frame `calibration_frame` of the capture) or "rest" (the BVH
  /// rest pose, all channels zero, e.g. a T-pose, against the mannequin's transfer of it).
  std::string calibration = "first";
  long long calibration_frame = 0;
  int max_iterations = 30;  ///< convergence loop per frame
  /// Start each frame from the previous solution (true) or from the frame's orientation
  /// transfer (false: no drift into a wrong local minimum over long captures).
  bool warm_start = false;
  double feet_tolerance = 1e-3, pelvis_tolerance = 2e-3, hands_tolerance = 2e-3;  ///< m/rad
};

struct RetargetFrame {
  VectorX q;
  SolveReport report;
};

class Retargeter {
 public:
  /// \throws std::invalid_argument naming an unknown segment/BVH joint, a bad calibration, or a
  /// map without the six controlled segments (pelvis, foot_l/r, hand_l/r, head).
  Retargeter(const Model& model, const skeleton::Bvh& bvh, const skeleton::BvhDriveMap& map,
             RetargetOptions options = {});

  /// Solves frame `frame` (negative counts from the end).
  RetargetFrame solve(long long frame);

  /// The controlled segments, in the order of their tasks.
  static const std::vector<std::string>& controlledSegments();
  const IkSolver& solver() const { return *solver_; }

 private:
  SE3 actorPose(const std::vector<SE3>& world, int s) const;

  const skeleton::Bvh& bvh_;
  skeleton::BvhDriver driver_;
  RetargetOptions options_;
  std::unique_ptr<IkSolver> solver_;
  std::vector<int> bvh_joint_;         ///< per controlled segment
  std::vector<SE3> offset_;            ///< O_s
  std::vector<FrameTask*> tasks_;
  PostureTask* posture_ = nullptr;
  double length_scale_ = 0.01;
  Matrix3 A_;
  VectorX q_;
  bool warm_ = false;
};

}  // namespace mannequin::ik
