// Part scores, adjustments and the assembly of RULA and REBA from measured angles. The bands are those of
// the sheets (McAtamney & Corlett 1993 Fig. 1–3; Hignett & McAtamney 2000 Fig. 1–2); where two bands meet
// at a value ("20–45°", "45–90°"), the value belongs to the lower band.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/ergonomics/tables.hpp"

namespace mannequin::ergonomics {

const char* toString(Side side) { return side == Side::kLeft ? "left" : "right"; }

int rulaUpperArmBase(double f) {
  if (f >= -20.0 && f <= 20.0) return 1;
  if (f < -20.0) return 2;  // extension beyond 20°
  if (f <= 45.0) return 2;
  if (f <= 90.0) return 3;
  return 4;
}

int rulaLowerArmBase(double e) { return e >= 60.0 && e <= 100.0 ? 1 : 2; }

int rulaWristBase(double f, double neutral) {
  const double a = std::abs(f);
  if (a <= neutral) return 1;
  return a <= 15.0 ? 2 : 3;
}

int rulaNeckBase(double f, double neutral) {
  if (f < -neutral) return 4;  // in extension
  if (f <= 10.0) return 1;
  return f <= 20.0 ? 2 : 3;
}

int rulaTrunkBase(double f, double neutral) {
  if (std::abs(f) <= neutral) return 1;  // upright (0°)
  if (f < 0) return 2;  // the sheet has no extension band: scored as the first band beyond 0° (our choice)
  if (f <= 20.0) return 2;
  return f <= 60.0 ? 3 : 4;
}

int rulaMuscleUse(const TaskInput& in) { return in.static_posture || in.repeated ? 1 : 0; }

int rulaForceLoad(const TaskInput& in) {
  if (in.shock) return 3;
  if (in.load_kg < 2.0) return 0;
  const bool sustained = in.static_posture || in.repeated;
  if (in.load_kg < 10.0) return sustained ? 2 : 1;
  return sustained ? 3 : 2;
}

int rulaActionLevel(int grand) {
  if (grand <= 2) return 1;
  if (grand <= 4) return 2;
  if (grand <= 6) return 3;
  return 4;
}

int rebaTrunkBase(double f, double neutral) {
  if (std::abs(f) <= neutral) return 1;  // upright
  if (f < -20.0) return 3;               // extension beyond 20°
  if (f < 0 || f <= 20.0) return 2;      // 0–20° flexion or extension
  return f <= 60.0 ? 3 : 4;
}

int rebaNeckBase(double f, double neutral) {
  if (f < -neutral) return 2;  // in extension
  return f <= 20.0 ? 1 : 2;
}

int rebaKneeAdjustment(double k) {
  if (k < 30.0) return 0;
  return k <= 60.0 ? 1 : 2;
}

int rebaUpperArmBase(double f) { return rulaUpperArmBase(f); }
int rebaLowerArmBase(double e) { return rulaLowerArmBase(e); }
int rebaWristBase(double f) { return std::abs(f) <= 15.0 ? 1 : 2; }

int rebaLoad(const TaskInput& in) {
  int s = in.load_kg < 5.0 ? 0 : (in.load_kg <= 10.0 ? 1 : 2);
  return s + (in.shock ? 1 : 0);
}

int rebaActivity(const TaskInput& in) {
  return (in.static_posture ? 1 : 0) + (in.repeated ? 1 : 0) + (in.rapid_large_changes ? 1 : 0);
}

int rebaActionLevel(int s) {
  if (s <= 1) return 0;
  if (s <= 3) return 1;
  if (s <= 7) return 2;
  if (s <= 10) return 3;
  return 4;
}

void checkTaskInput(const TaskInput& in) {
  if (!std::isfinite(in.load_kg))
    throw std::invalid_argument("ergonomics: TaskInput.load_kg is not finite");
  if (in.load_kg < 0)
    throw std::invalid_argument("ergonomics: TaskInput.load_kg = " + std::to_string(in.load_kg) +
                                " kg is negative");
  const int c = static_cast<int>(in.coupling);
  if (c < 0 || c > 3)
    throw std::invalid_argument("ergonomics: TaskInput.coupling = " + std::to_string(c) + " is not 0..3");
}

void checkThresholds(const Thresholds& t) {
  const auto bad = [](const char* what, double v) {
    throw std::invalid_argument(std::string("ergonomics: Thresholds.") + what + " = " + std::to_string(v) +
                                " is out of range");
  };
  const auto angle = [&](const char* what, double v) {
    if (!std::isfinite(v) || v < 0 || v > 90) bad(what, v);
  };
  angle("neutral_deg", t.neutral_deg);
  angle("twist_deg", t.twist_deg);
  angle("side_bend_deg", t.side_bend_deg);
  angle("abduction_deg", t.abduction_deg);
  angle("shoulder_raised_deg", t.shoulder_raised_deg);
  angle("wrist_deviation_deg", t.wrist_deviation_deg);
  if (!std::isfinite(t.twist_mid_fraction) || t.twist_mid_fraction < 0 || t.twist_mid_fraction > 1)
    bad("twist_mid_fraction", t.twist_mid_fraction);
  if (!std::isfinite(t.out_to_side_m) || t.out_to_side_m < 0) bad("out_to_side_m", t.out_to_side_m);
}

namespace {
/// The angles a caller built (scoreRula/scoreReba are public): finite, a valid side, a sane neutral band.
/// \throws std::invalid_argument naming the field.
void checkAngles(const PostureAngles& p, Side side) {
  if (side != Side::kLeft && side != Side::kRight) throw std::invalid_argument("ergonomics: side must be left or right");
  if (!std::isfinite(p.neutral_deg) || p.neutral_deg < 0 || p.neutral_deg > 45)
    throw std::invalid_argument("ergonomics: neutral_deg must be in [0, 45] (got " + std::to_string(p.neutral_deg) + ")");
  const auto check = [](double v, const char* what) {
    if (!std::isfinite(v)) throw std::invalid_argument(std::string("ergonomics: angle ") + what + " is not finite");
  };
  const BodyAngles& b = p.body;
  check(b.trunk_flexion_deg, "trunk_flexion_deg");
  check(b.trunk_side_bend_deg, "trunk_side_bend_deg");
  check(b.trunk_twist_deg, "trunk_twist_deg");
  check(b.neck_flexion_deg, "neck_flexion_deg");
  check(b.neck_side_bend_deg, "neck_side_bend_deg");
  check(b.neck_twist_deg, "neck_twist_deg");
  check(b.knee_flexion_deg[0], "knee_flexion_deg[0]");
  check(b.knee_flexion_deg[1], "knee_flexion_deg[1]");
  const ArmAngles& a = p.arm[static_cast<int>(side)];
  check(a.upper_arm_flexion_deg, "upper_arm_flexion_deg");
  check(a.upper_arm_abduction_deg, "upper_arm_abduction_deg");
  check(a.shoulder_elevation_deg, "shoulder_elevation_deg");
  check(a.elbow_flexion_deg, "elbow_flexion_deg");
  check(a.wrist_flexion_deg, "wrist_flexion_deg");
  check(a.wrist_deviation_deg, "wrist_deviation_deg");
  check(a.forearm_rotation_deg, "forearm_rotation_deg");
  check(a.forearm_rotation_fraction, "forearm_rotation_fraction");
  check(a.wrist_lateral_m, "wrist_lateral_m");
  check(a.shoulder_lateral_m, "shoulder_lateral_m");
}
}  // namespace

RulaSide scoreRula(const PostureAngles& angles, Side side, const TaskInput& in) {
  checkTaskInput(in);
  checkAngles(angles, side);
  const ArmAngles& a = angles.arm[static_cast<int>(side)];
  const BodyAngles& b = angles.body;
  const double neutral = angles.neutral_deg;
  RulaSide r;
  r.upper_arm_base = rulaUpperArmBase(a.upper_arm_flexion_deg);
  r.upper_arm = std::clamp(r.upper_arm_base + (a.shoulder_raised ? 1 : 0) + (a.arm_abducted ? 1 : 0) -
                               (in.arm_supported ? 1 : 0),
                           1, 6);
  r.lower_arm_base = rulaLowerArmBase(a.elbow_flexion_deg);
  r.lower_arm = r.lower_arm_base + (a.across_midline || a.out_to_side ? 1 : 0);
  r.wrist_base = rulaWristBase(a.wrist_flexion_deg, neutral);
  r.wrist = r.wrist_base + (a.wrist_deviated ? 1 : 0);
  r.wrist_twist = a.wrist_twist_at_end ? 2 : 1;
  r.posture_a = rulaTableA(r.upper_arm, r.lower_arm, r.wrist, r.wrist_twist);
  r.muscle_use = rulaMuscleUse(in);
  r.force_load = rulaForceLoad(in);
  r.score_c = r.posture_a + r.muscle_use + r.force_load;
  r.neck_base = rulaNeckBase(b.neck_flexion_deg, neutral);
  r.neck = r.neck_base + (b.neck_twisted ? 1 : 0) + (b.neck_side_bent ? 1 : 0);
  r.trunk_base = rulaTrunkBase(b.trunk_flexion_deg, neutral);
  r.trunk = r.trunk_base + (b.trunk_twisted ? 1 : 0) + (b.trunk_side_bent ? 1 : 0);
  r.legs = in.legs_supported ? 1 : 2;
  r.posture_b = rulaTableB(r.neck, r.trunk, r.legs);
  r.score_d = r.posture_b + r.muscle_use + r.force_load;
  r.grand = rulaTableC(r.score_c, r.score_d);
  r.action_level = rulaActionLevel(r.grand);
  return r;
}

RebaSide scoreReba(const PostureAngles& angles, Side side, const TaskInput& in) {
  checkTaskInput(in);
  checkAngles(angles, side);
  const ArmAngles& a = angles.arm[static_cast<int>(side)];
  const BodyAngles& b = angles.body;
  const double neutral = angles.neutral_deg;
  RebaSide r;
  r.trunk_base = rebaTrunkBase(b.trunk_flexion_deg, neutral);
  r.trunk = r.trunk_base + (b.trunk_twisted || b.trunk_side_bent ? 1 : 0);
  r.neck_base = rebaNeckBase(b.neck_flexion_deg, neutral);
  r.neck = r.neck_base + (b.neck_twisted || b.neck_side_bent ? 1 : 0);
  r.legs_base = in.legs_supported ? 1 : 2;
  const double knee = std::max(b.knee_flexion_deg[0], b.knee_flexion_deg[1]);
  r.legs = r.legs_base + (in.sitting ? 0 : rebaKneeAdjustment(knee));
  r.table_a = rebaTableA(r.trunk, r.neck, r.legs);
  r.load = rebaLoad(in);
  r.score_a = r.table_a + r.load;
  r.upper_arm_base = rebaUpperArmBase(a.upper_arm_flexion_deg);
  r.upper_arm = std::clamp(r.upper_arm_base + (a.shoulder_raised ? 1 : 0) + (a.arm_abducted ? 1 : 0) -
                               (in.arm_supported ? 1 : 0),
                           1, 6);
  r.lower_arm = rebaLowerArmBase(a.elbow_flexion_deg);
  r.wrist_base = rebaWristBase(a.wrist_flexion_deg);
  r.wrist = r.wrist_base + (a.wrist_deviated || a.wrist_twist_at_end ? 1 : 0);
  r.table_b = rebaTableB(r.upper_arm, r.lower_arm, r.wrist);
  r.coupling = static_cast<int>(in.coupling);
  r.score_b = r.table_b + r.coupling;
  r.table_c = rebaTableC(r.score_a, r.score_b);
  r.activity = rebaActivity(in);
  r.score = r.table_c + r.activity;
  r.action_level = rebaActionLevel(r.score);
  return r;
}

}  // namespace mannequin::ergonomics
