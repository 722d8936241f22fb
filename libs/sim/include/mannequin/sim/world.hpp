#pragma once
/// \file world.hpp
/// \brief The simulated world the sim service steps: mannequins driven by calibrated mocap bodies.
///
/// Time: the World steps by a fixed δt (SimConfig::step). Its clock is tied to the capture clock of the
/// mocap stream by anchor(): capture time = anchor capture time + (World time − anchor World time) −
/// interpolation_delay. Targets are sampled from the MocapBuffer at that capture time.
///
/// Calibration (thesis Fig. 1.10): at the first frame where every body driving a mannequin is tracked
/// and (if `calibration_needs_flag`) the frame is flagged as the calibration pose, the mannequin is put
/// in its calibration configuration q_c (standing, root moved horizontally under the body driving the
/// root frame, then fitted for `calibration_fit_steps` tracker steps so that every control frame's origin
/// reaches its body's position) and each control frame f driven by body b keeps the offset
/// bMf = oMb(c)⁻¹ · oMf(q_c); q_c is also the posture target;
/// afterwards its target is oMd(t) = oMb(t) · bMf (world frame), and its target twist (when
/// `target_twist` is on) the body twist of two consecutive targets, V_d = (log(R_{k−1}ᵀR_k), R_kᵀ(p_k −
/// p_{k−1}))/δt, set to zero when it exceeds `max_target_speed` (a jump, not a motion).
///
/// Stepping: each mannequin has a Stepper (stepper.hpp): a control::Controller when its setup carries
/// a controller config (ControllerStepper, the default of the sim service), else the KinematicTracker.
/// The calibration fit always uses a KinematicTracker (it is an inverse-kinematics problem).
///
/// Occlusion policy (per control frame): while its body is untracked the target holds the last
/// tracked pose for `occlusion_hold` s, then the frame's weight decreases linearly to 0 over
/// `occlusion_blend` s, so the posture control takes the limb back to the posture target; when the body
/// is tracked again the weight rises back to 1 over `occlusion_blend` s (no jump).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/sim/mocap_buffer.hpp"
#include "mannequin/constraints/joint_limits.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/sim/stepper.hpp"
#include "mannequin/sim/tracker.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::sim {

/// A control frame driven by a mocap body.
struct ControlFrameSpec {
  std::string frame;  ///< model frame (e.g. "hand_l", "palm_l", "pelvis")
  std::string body;   ///< mocap body name
};

struct MannequinSetup {
  std::string name;             ///< instance name in sim.world
  skeleton::Model model;        ///< built from configs/mannequins/*.yaml by the caller
  std::vector<ControlFrameSpec> frames;
  std::string root_frame = "pelvis";  ///< frame whose body places the mannequin at calibration
  /// The controller's config (configs/control/*.yaml): steps the mannequin with a ControllerStepper.
  /// Empty: the KinematicTracker with SimConfig::gains.
  std::optional<control::ControllerConfig> controller;
};

struct SimConfig {
  double step = 0.001;                 ///< δt (s)
  double interpolation_delay = 0.0;    ///< s behind the newest capture time (live mode smoothing)
  double occlusion_hold = 0.3;         ///< s
  double occlusion_blend = 0.5;        ///< s
  bool calibration_needs_flag = false; ///< calibrate only on frames flagged calibration_pose
  /// Steps of posture fitting at calibration: q_c is first pulled so that every control frame's origin
  /// reaches its body's position (orientations free), from standing; 0 = use the standing posture as is.
  int calibration_fit_steps = 0;
  TrackerGains gains;                  ///< KinematicTracker gains (stepper: kinematic, calibration fit)
  bool target_twist = true;            ///< feed the targets' velocities forward (ControllerStepper)
  double max_target_speed = 10.0;      ///< m/s (and rad/s × 0.3 m): faster target motion is a jump
  /// Joint limits as unilateral constraints in the ControllerStepper (nullopt: off). The kinematic
  /// tracker always clamps to the limits.
  std::optional<constraints::JointLimitOptions> joint_limits = constraints::JointLimitOptions{};
};

/// A control frame driven by a mocap body, after a step: the World's calibration (bMf), the target it
/// derives from the body, and how well the mannequin follows it. The controller's coupling on the same
/// frame (gains, wrench, port energy) is control::ControlFrameState. The wire's v1::ControlFrameState is
/// filled from this.
struct DrivenFrame {
  std::string frame, body;
  int frame_index = -1;
  math::SE3 offset;         ///< bMf from calibration
  math::SE3 target;         ///< world
  math::SE3 actual;         ///< world
  bool tracked = false;
  double weight = 0.0;
  double position_error = 0.0;     ///< m
  double orientation_error = 0.0;  ///< rad
};

class World {
 public:
  /// \throws std::invalid_argument naming an unknown frame (with the model's frames), a step <= 0,
  /// or two mannequins with the same name.
  World(std::vector<MannequinSetup> mannequins, const SimConfig& config);
  ~World();

  /// Adds a mocap frame (ignored if not newer than the last). Calibrates mannequins when possible.
  void addMocap(const mocap::Frame& frame);
  /// Ties the World clock to the capture clock: now, capture time is `capture_ns`.
  void anchor(std::int64_t capture_ns);
  bool anchored() const { return anchored_; }
  /// Capture time the next step samples targets at (ns).
  std::int64_t captureTimeNs() const;
  /// One fixed step. Returns false if a mannequin's step failed numerically (its state is kept).
  bool step();

  double time() const { return static_cast<double>(steps_) * config_.step; }
  std::uint64_t stepCount() const { return steps_; }
  const SimConfig& config() const { return config_; }
  int numMannequins() const { return static_cast<int>(mannequins_.size()); }
  const std::string& name(int m) const;
  const skeleton::Model& model(int m) const;
  const skeleton::Data& data(int m) const;      ///< kinematics at q (oMi, oMf, com after step)
  const skeleton::VectorX& q(int m) const;
  const skeleton::VectorX& qdot(int m) const;
  bool calibrated(int m) const;
  /// The mannequin's stepper (kind(), and for a ControllerStepper its controller).
  const Stepper& stepper(int m) const;
  const std::vector<DrivenFrame>& controlFrames(int m) const;
  /// The newest mocap frame added (nullptr before any).
  const mocap::Frame* latestMocap() const { return buffer_.newest(); }
  std::uint64_t failedSteps() const { return failed_steps_; }

 private:
  struct Mannequin;
  void calibrate(Mannequin& m, const mocap::Frame& frame);
  math::Vector6 targetTwist(Mannequin& m, std::size_t i, double dt) const;
  std::vector<std::unique_ptr<Mannequin>> mannequins_;
  SimConfig config_;
  MocapBuffer buffer_;
  std::uint64_t steps_ = 0, failed_steps_ = 0;
  bool anchored_ = false;
  std::int64_t anchor_capture_ns_ = 0;
  std::uint64_t anchor_step_ = 0;
};

}  // namespace mannequin::sim
