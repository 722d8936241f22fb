#pragma once
/// \file ergonomics.hpp
/// \brief Per-frame ergonomic scores of a mannequin's posture (issue 18): RULA (McAtamney & Corlett 1993,
/// Applied Ergonomics 24(2):91–99) and REBA (Hignett & McAtamney 2000, Applied Ergonomics 31(2):201–205),
/// left and right sides scored separately; joint-limit proximity; reach checks. docs/ergonomics.md says
/// how every angle is measured on the skeleton, the tables, the adjustments and the defaults.
///
/// The posture is (model, q): the body-part angles are measured geometrically from segment directions
/// after forward kinematics (world z up; the body's forward is the pelvis's x axis), never read off
/// single coordinates, so a bend made of lumbar + thoracic + root rotations counts as one trunk bend.
#include <array>
#include <string>
#include <vector>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::ergonomics {

using skeleton::Vector3;
using skeleton::VectorX;

enum class Side { kLeft = 0, kRight = 1 };
const char* toString(Side side);  ///< "left", "right"

/// REBA coupling (hand hold) quality: good 0, fair +1, poor +2, unacceptable +3.
enum class Coupling { kGood = 0, kFair = 1, kPoor = 2, kUnacceptable = 3 };

/// What joint angles cannot tell. The defaults describe a posture held briefly, nothing in the hands,
/// standing evenly on both feet: with them the scores are those of the posture alone.
struct TaskInput {
  double load_kg = 0.0;          ///< load or force handled (kg, ≥ 0, finite), per hand
  bool shock = false;            ///< shock or forces with a rapid build-up (RULA force 3; REBA load +1)
  bool static_posture = false;   ///< posture mainly static, held > 1 min (RULA muscle use +1; REBA activity +1)
  bool repeated = false;         ///< action repeated ≥ 4 times/min (RULA muscle use +1; REBA activity +1)
  bool rapid_large_changes = false;  ///< REBA activity +1: rapid large changes in posture or an unstable base
  bool arm_supported = false;    ///< arm supported or person leaning (RULA and REBA upper arm −1)
  bool legs_supported = true;    ///< legs and feet supported, weight evenly balanced (RULA legs 1 else 2;
                                 ///< REBA legs: bilateral weight bearing 1, else 2)
  bool sitting = false;          ///< REBA: no knee-flexion adjustment when sitting
  Coupling coupling = Coupling::kGood;  ///< REBA coupling
};

/// Where the sheets say "neutral", "twisted", "abducted", "raised" without a number, these decide.
/// Our choices (docs/ergonomics.md, "Thresholds"); angles in degrees.
struct Thresholds {
  double neutral_deg = 5.0;          ///< |angle| ≤ this is the sheets' 0° (trunk upright, wrist neutral,
                                     ///< neck not in extension)
  double twist_deg = 10.0;           ///< trunk / neck twisted beyond this
  double side_bend_deg = 10.0;       ///< trunk / neck side-bent beyond this
  double abduction_deg = 20.0;       ///< upper arm abducted beyond this
  double shoulder_raised_deg = 10.0; ///< clavicle elevated above its rest direction by more than this
  double wrist_deviation_deg = 10.0; ///< wrist radially/ulnarly deviated beyond this
  double twist_mid_fraction = 0.5;   ///< forearm rotation inside the middle fraction of its range = mid-range
  double out_to_side_m = 0.10;       ///< wrist farther from the midsagittal plane than the shoulder by more
};

/// Angles of one arm, measured in the thorax frame (degrees unless said).
struct ArmAngles {
  double upper_arm_flexion_deg = 0;   ///< elevation of the upper arm from the trunk's downward axis, negative
                                      ///< (extension) when the arm points more backward than sideways
  double upper_arm_abduction_deg = 0; ///< angle of the upper arm out of the trunk's sagittal plane, outward +
  double shoulder_elevation_deg = 0;  ///< clavicle direction above its rest direction (thorax frame)
  double elbow_flexion_deg = 0;       ///< angle between the upper arm and the forearm (0 straight)
  double wrist_flexion_deg = 0;       ///< hand against the forearm, toward the palm + (extension −)
  double wrist_deviation_deg = 0;     ///< hand out of the forearm's flexion plane, radial +
  double forearm_rotation_deg = 0;    ///< pronation from full supination (forearm about its axis vs the upper arm)
  double forearm_rotation_fraction = 0;  ///< where in its range (0 = one end, 1 = the other)
  double wrist_lateral_m = 0;         ///< wrist's distance from the midsagittal plane, toward this arm's side +
  double shoulder_lateral_m = 0;      ///< shoulder's distance from the midsagittal plane, toward this side +
  bool shoulder_raised = false, arm_abducted = false;
  bool across_midline = false, out_to_side = false;
  bool wrist_deviated = false, wrist_twist_at_end = false;
};

/// Trunk, neck and knees (degrees).
struct BodyAngles {
  double trunk_flexion_deg = 0;    ///< thorax long axis from world vertical, in the pelvis's sagittal plane
  double trunk_side_bend_deg = 0;  ///< thorax long axis out of that plane, to the left +
  double trunk_twist_deg = 0;      ///< thorax against the pelvis about the long axis, to the left +
  double neck_flexion_deg = 0;     ///< head long axis against the thorax, forward +
  double neck_side_bend_deg = 0;   ///< to the left +
  double neck_twist_deg = 0;       ///< head against thorax about the head's long axis, to the left +
  std::array<double, 2> knee_flexion_deg{};  ///< angle between thigh and shank [left, right]
  bool trunk_twisted = false, trunk_side_bent = false, neck_twisted = false, neck_side_bent = false;
};

struct PostureAngles {
  double neutral_deg = 5.0;  ///< Thresholds::neutral_deg of the measurement: the sheets' "0°" band
  BodyAngles body;
  std::array<ArmAngles, 2> arm{};  ///< [left, right]
};

/// RULA for one side: every intermediate score, as on the sheet.
struct RulaSide {
  int upper_arm_base = 0, upper_arm = 0;  ///< position score, then with raised/abducted/supported
  int lower_arm_base = 0, lower_arm = 0;  ///< then with across midline / out to the side
  int wrist_base = 0, wrist = 0;          ///< then with deviation
  int wrist_twist = 0;
  int posture_a = 0;                      ///< Table A
  int muscle_use = 0, force_load = 0;     ///< the same for both groups (one TaskInput)
  int score_c = 0;                        ///< posture A + muscle use + force/load
  int neck_base = 0, neck = 0;            ///< then with twist / side bend
  int trunk_base = 0, trunk = 0;
  int legs = 0;
  int posture_b = 0;                      ///< Table B
  int score_d = 0;                        ///< posture B + muscle use + force/load
  int grand = 0;                          ///< Table C (1–7)
  int action_level = 0;                   ///< 1 (1–2 acceptable) … 4 (7: investigate and change now)
};

/// REBA for one side: every intermediate score, as on the sheet.
struct RebaSide {
  int trunk_base = 0, trunk = 0;       ///< then with twist / side bend
  int neck_base = 0, neck = 0;
  int legs_base = 0, legs = 0;         ///< then with knee flexion
  int table_a = 0, load = 0, score_a = 0;
  int upper_arm_base = 0, upper_arm = 0;
  int lower_arm = 0;
  int wrist_base = 0, wrist = 0;       ///< then with deviated / twisted
  int table_b = 0, coupling = 0, score_b = 0;
  int table_c = 0, activity = 0;
  int score = 0;                       ///< REBA score (1–15)
  int action_level = 0;                ///< 0 negligible (1), 1 low (2–3), 2 medium (4–7), 3 high (8–10), 4 very high (11–15)
};

struct Assessment {
  PostureAngles angles;
  std::array<RulaSide, 2> rula{};  ///< [left, right]
  std::array<RebaSide, 2> reba{};
};

// ---- part scores from angles (the sheets' bands; exposed for tests and reports) ----------------------
int rulaUpperArmBase(double flexion_deg);  ///< −20..20: 1; extension > 20 or 20–45: 2; 45–90: 3; > 90: 4
int rulaLowerArmBase(double elbow_deg);    ///< 60–100: 1; else 2
int rulaWristBase(double flexion_deg, double neutral_deg);  ///< neutral: 1; ≤ 15: 2; > 15: 3
int rulaNeckBase(double flexion_deg, double neutral_deg);   ///< 0–10: 1; 10–20: 2; > 20: 3; extension: 4
int rulaTrunkBase(double flexion_deg, double neutral_deg);  ///< 0°: 1; 0–20: 2; 20–60: 3; > 60: 4
int rulaMuscleUse(const TaskInput& input);  ///< 1 if static > 1 min or repeated ≥ 4/min
int rulaForceLoad(const TaskInput& input);  ///< 0 (< 2 kg intermittent) … 3 (≥ 10 kg static/repeated, or shock)
int rulaActionLevel(int grand);
int rebaTrunkBase(double flexion_deg, double neutral_deg);  ///< upright 1; 0–20 flex/ext 2; 20–60 or ext > 20: 3; > 60: 4
int rebaNeckBase(double flexion_deg, double neutral_deg);   ///< 0–20: 1; > 20 or extension: 2
int rebaKneeAdjustment(double knee_deg);   ///< 30–60: +1; > 60: +2
int rebaUpperArmBase(double flexion_deg);  ///< same bands as RULA
int rebaLowerArmBase(double elbow_deg);    ///< 60–100: 1; else 2
int rebaWristBase(double flexion_deg);     ///< 0–15: 1; > 15: 2
int rebaLoad(const TaskInput& input);      ///< < 5 kg 0; 5–10: 1; > 10: 2; shock +1
int rebaActivity(const TaskInput& input);  ///< +1 each: static, repeated, rapid large changes
int rebaActionLevel(int score);

/// Checks a TaskInput. \throws std::invalid_argument naming the field (negative or non-finite load).
void checkTaskInput(const TaskInput& input);
void checkThresholds(const Thresholds& t);

/// RULA / REBA of one side from measured angles.
RulaSide scoreRula(const PostureAngles& angles, Side side, const TaskInput& input);
RebaSide scoreReba(const PostureAngles& angles, Side side, const TaskInput& input);

/// Fraction of a joint's range used, from the anatomical zero toward the limit in that direction
/// (q ≥ 0: q / upper, q < 0: q / lower; when 0 is outside the range, the position in the range).
struct JointLimitUse {
  std::string joint;
  double fraction = 0;      ///< the largest over the joint's coordinates (> 1 past a limit)
  int coordinate = -1;      ///< index in q of that coordinate
};
struct JointLimitReport {
  std::vector<JointLimitUse> joints;  ///< every joint with finite limits, in model order
  int worst = -1;                     ///< index in `joints` of the largest fraction
};

/// A target against one arm's reach: distance from the shoulder joint centre against the arm's length
/// (shoulder → elbow → wrist → palm frame, straight).
struct ReachResult {
  Vector3 shoulder = Vector3::Zero();  ///< shoulder joint centre, world (m)
  double distance = 0;    ///< |target − shoulder| (m)
  double arm_length = 0;  ///< (m)
  double miss = 0;        ///< max(0, distance − arm_length) (m): by how much it is out of reach
  bool reachable = true;  ///< distance ≤ arm_length
};

/// Scores postures of one model. Keeps a Data (forward kinematics) and the joint indices; one per thread.
class Evaluator {
 public:
  /// \throws std::invalid_argument naming what is missing when the model lacks a joint or frame of the
  /// mannequin (skeleton::buildMannequin) or the thresholds are bad.
  explicit Evaluator(const skeleton::Model& model, const Thresholds& thresholds = {});

  /// Angles of posture q. \throws std::invalid_argument on a q of the wrong size or a non-finite
  /// coordinate (named).
  PostureAngles measure(const VectorX& q);
  /// Angles, RULA and REBA of both sides.
  Assessment evaluate(const VectorX& q, const TaskInput& input = {});
  /// The same from kinematics the caller already has (skeleton::forwardKinematics of this model: oMi and
  /// oMf), e.g. the sim's after a step: no forward kinematics again. \throws std::invalid_argument on a
  /// data of another size or a non-finite pose (named).
  PostureAngles measure(const skeleton::Data& data);
  Assessment evaluate(const skeleton::Data& data, const TaskInput& input = {});
  JointLimitReport jointLimits(const VectorX& q) const;
  /// \throws std::invalid_argument on a non-finite target.
  ReachResult reach(const VectorX& q, Side side, const Vector3& target);
  double armLength(Side side) const { return arm_length_[static_cast<int>(side)]; }
  const Thresholds& thresholds() const { return thresholds_; }

 private:
  void checkQ(const VectorX& q) const;
  PostureAngles angles(const skeleton::Data& data) const;
  const skeleton::Model& model_;
  Thresholds thresholds_;
  skeleton::Data data_;
  int root_, thoracic_, neck_, head_top_;
  struct ArmIds {
    int clavicle, shoulder, elbow, radioulnar, wrist, wrist_dev, palm;
  };
  std::array<ArmIds, 2> arm_{};
  std::array<int, 2> hip_{}, knee_{}, ankle_{};
  std::array<double, 2> arm_length_{};
  std::array<double, 2> clavicle_rest_deg_{};
};

}  // namespace mannequin::ergonomics
