// RULA (McAtamney & Corlett 1993) and REBA (Hignett & McAtamney 2000) on postures of the 50th-percentile
// male built by setting joint coordinates; every expected score is worked out by hand from the sheets in
// the comments (table cells as [row][column] in the sheets' 1-based scores). Then part-score bands,
// monotonicity along swept joints, the load/force adjustments, joint-limit use, reach and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin::ergonomics;
namespace sk = mannequin::skeleton;

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr int L = 0, R = 1;

struct Fixture {
  sk::Model model = sk::buildMannequin(sk::MannequinSpec{});  // male, 1.75 m, 75 kg
  Evaluator eval{model};
  sk::VectorX standing() const { return sk::standingConfiguration(model); }
  // a relaxed standing posture: both forearms in mid-rotation (radioulnar 80° of 0..160: palms facing the
  // thighs), so the wrist twist is "mid-range"
  sk::VectorX relaxed() const {
    sk::VectorX q = standing();
    set(q, "radioulnar_l", 80);
    set(q, "radioulnar_r", 80);
    return q;
  }
  void set(sk::VectorX& q, const std::string& coord, double deg) const {
    const auto names = model.coordinateNames();
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == coord) {
        q(static_cast<int>(i)) = deg * kDeg;
        return;
      }
    throw std::invalid_argument("test: no coordinate " + coord);
  }
};
}  // namespace

// Standing, anatomical posture (palms forward = forearm fully supinated, the end of its range).
// RULA: upper arm 0° → 1; elbow straight (0°, outside 60–100) → lower arm 2; wrist 0° → 1, no deviation;
// twist at the end of the range → 2; Table A[1][2][1][2] = 2; no muscle use, no load → score C = 2.
// Neck 0° → 1, trunk 0° → 1, legs supported → 1; Table B[1][1][1] = 1 → score D = 1; Table C[2][1] = 2.
// Grand score 2, action level 1. REBA: trunk 1, neck 1, legs 1 (knees straight) → Table A = 1, load 0 →
// score A 1; upper arm 1, lower arm 2, wrist 1 + 1 (twisted) = 2 → Table B[1][2][2] = 2, coupling good →
// score B 2; Table C[1][2] = 1; no activity → REBA 1 (negligible, action level 0).
TEST(Rula, StandingAnatomicalPostureScores2AndReba1) {
  Fixture f;
  const Assessment a = f.eval.evaluate(f.standing());
  for (int s : {L, R}) {
    const RulaSide& r = a.rula[s];
    EXPECT_EQ(r.upper_arm, 1);
    EXPECT_EQ(r.lower_arm, 2);
    EXPECT_EQ(r.wrist, 1);
    EXPECT_EQ(r.wrist_twist, 2);
    EXPECT_EQ(r.posture_a, 2);
    EXPECT_EQ(r.score_c, 2);
    EXPECT_EQ(r.neck, 1);
    EXPECT_EQ(r.trunk, 1);
    EXPECT_EQ(r.legs, 1);
    EXPECT_EQ(r.posture_b, 1);
    EXPECT_EQ(r.grand, 2);
    EXPECT_EQ(r.action_level, 1);
    const RebaSide& b = a.reba[s];
    EXPECT_EQ(b.table_a, 1);
    EXPECT_EQ(b.wrist, 2);
    EXPECT_EQ(b.table_b, 2);
    EXPECT_EQ(b.score, 1);
    EXPECT_EQ(b.action_level, 0);
  }
  EXPECT_NEAR(a.angles.body.trunk_flexion_deg, 0.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_flexion_deg, 0.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[R].elbow_flexion_deg, 0.0, 1e-6);
}

// Relaxed standing (forearms mid-rotation): RULA twist 1, Table A[1][2][1][1] = 2, C = 2, D = 1,
// Table C[2][1] = 2. REBA wrist 1 → Table B[1][2][1] = 1, Table C[1][1] = 1.
TEST(Rula, RelaxedStandingScores2AndReba1) {
  Fixture f;
  const Assessment a = f.eval.evaluate(f.relaxed());
  for (int s : {L, R}) {
    EXPECT_EQ(a.rula[s].wrist_twist, 1);
    EXPECT_EQ(a.rula[s].grand, 2);
    EXPECT_EQ(a.reba[s].score, 1);
    EXPECT_NEAR(a.angles.arm[s].forearm_rotation_deg, 80.0, 1e-9);
  }
}

// Left shoulder flexed 100° (arm forward and up): RULA upper arm > 90° → 4; lower arm 2 (straight),
// wrist 1, twist 1 → Table A[4][2][1][1] = 4 → C = 4; D = 1 → Table C[4][1] = 3 (action level 2).
// The right side stays relaxed: 2. REBA left: upper arm 4, lower arm 2, wrist 1 → Table B[4][2][1] = 5,
// score A 1 → Table C[1][5] = 3.
TEST(Rula, ShoulderFlexed100GivesUpperArm4) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "shoulder_l.y", -100);  // flexion is about −y (docs/mannequin-model.md)
  const Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_flexion_deg, 100.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_abduction_deg, 0.0, 1e-9);
  EXPECT_EQ(a.rula[L].upper_arm, 4);
  EXPECT_EQ(a.rula[L].posture_a, 4);
  EXPECT_EQ(a.rula[L].grand, 3);
  EXPECT_EQ(a.rula[L].action_level, 2);
  EXPECT_EQ(a.rula[R].grand, 2);
  EXPECT_EQ(a.reba[L].upper_arm, 4);
  EXPECT_EQ(a.reba[L].table_b, 5);
  EXPECT_EQ(a.reba[L].score, 3);
  EXPECT_EQ(a.reba[R].score, 1);
}

// The mirror image scores the same on the other side.
TEST(Rula, LeftAndRightAreMirrorImages) {
  Fixture f;
  sk::VectorX ql = f.relaxed(), qr = f.relaxed();
  f.set(ql, "shoulder_l.y", -60);
  f.set(ql, "shoulder_l.x", 30);   // abduction +x on the left
  f.set(qr, "shoulder_r.y", -60);
  f.set(qr, "shoulder_r.x", -30);  // mirrored: −x on the right
  f.set(ql, "elbow_l", 45);
  f.set(qr, "elbow_r", 45);
  const Assessment a = f.eval.evaluate(ql), b = f.eval.evaluate(qr);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_abduction_deg, b.angles.arm[R].upper_arm_abduction_deg, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_flexion_deg, b.angles.arm[R].upper_arm_flexion_deg, 1e-9);
  EXPECT_GT(a.angles.arm[L].upper_arm_abduction_deg, 20.0);
  EXPECT_EQ(a.rula[L].upper_arm, b.rula[R].upper_arm);
  EXPECT_EQ(a.rula[L].grand, b.rula[R].grand);
  EXPECT_EQ(a.reba[L].score, b.reba[R].score);
}

// Elbow 30° (arm hanging): lower arm 0–60° → 2. Elbow 80°: 60–100° → 1, and then RULA Table A[1][1][1][1]
// = 1, C = 1, D = 1 → Table C[1][1] = 1, the lowest grand score; REBA Table B[1][1][1] = 1 → REBA 1.
// Elbow 120°: > 100° → 2.
TEST(Rula, ElbowBands) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "elbow_l", 30);
  Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.arm[L].elbow_flexion_deg, 30.0, 1e-6);
  EXPECT_EQ(a.rula[L].lower_arm, 2);
  f.set(q, "elbow_l", 80);
  a = f.eval.evaluate(q);
  EXPECT_EQ(a.rula[L].lower_arm, 1);
  EXPECT_EQ(a.rula[L].posture_a, 1);
  EXPECT_EQ(a.rula[L].grand, 1);
  EXPECT_EQ(a.reba[L].lower_arm, 1);
  EXPECT_EQ(a.reba[L].score, 1);
  f.set(q, "elbow_l", 120);
  EXPECT_EQ(f.eval.evaluate(q).rula[L].lower_arm, 2);
}

// Trunk flexed 30° (lumbar 15° + thoracic 15°, flexion about +y): RULA trunk 20–60° → 3; the arms hang
// along the trunk, so they are at 0° to it. Table B[neck 1][trunk 3][legs 1] = 3 → D = 3; C = 2 →
// Table C[2][3] = 3. REBA: trunk 3, neck 1, legs 1 → Table A[3][1][1] = 2 → score A 2; score B 1 →
// Table C[2][1] = 1 → REBA 1.
TEST(Rula, TrunkFlexed30GivesTrunk3) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "lumbar.y", 15);
  f.set(q, "thoracic.y", 15);
  const Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.body.trunk_flexion_deg, 30.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_flexion_deg, 0.0, 1e-9);
  EXPECT_EQ(a.rula[L].trunk, 3);
  EXPECT_EQ(a.rula[L].posture_b, 3);
  EXPECT_EQ(a.rula[L].grand, 3);
  EXPECT_EQ(a.reba[L].trunk, 3);
  EXPECT_EQ(a.reba[L].table_a, 2);
  EXPECT_EQ(a.reba[L].score, 1);
}

// The trunk's flexion is measured from the world vertical: the whole body pitched forward 30° at the root
// (a fall, or a mannequin leaning on a support) reads trunk 30°, the neck and arms unchanged against it.
TEST(Rula, TrunkFlexionIsAgainstTheVertical) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "root.ry", 30);  // the root's rotation vector, y component
  const Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.body.trunk_flexion_deg, 30.0, 1e-9);
  EXPECT_NEAR(a.angles.body.neck_flexion_deg, 0.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[R].upper_arm_flexion_deg, 0.0, 1e-9);
  EXPECT_EQ(a.rula[R].trunk, 3);
}

// Neck flexed 25°: RULA neck > 20° → 3, Table B[3][1][1] = 3, Table C[2][3] = 3. REBA neck > 20° → 2,
// Table A[trunk 1][neck 2][legs 1] = 1 → REBA 1. Neck in extension (−15°): RULA 4, REBA 2.
TEST(Rula, NeckFlexed25GivesNeck3) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "neck.y", 25);
  Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.body.neck_flexion_deg, 25.0, 1e-9);
  EXPECT_EQ(a.rula[L].neck, 3);
  EXPECT_EQ(a.rula[L].posture_b, 3);
  EXPECT_EQ(a.rula[L].grand, 3);
  EXPECT_EQ(a.reba[L].neck, 2);
  EXPECT_EQ(a.reba[L].score, 1);
  f.set(q, "neck.y", -15);
  a = f.eval.evaluate(q);
  EXPECT_EQ(a.rula[L].neck_base, 4);
  EXPECT_EQ(a.reba[L].neck_base, 2);
}

// Twist and side bend: lumbar turned 15° about its long axis → trunk twisted (> 10°): RULA trunk 1 + 1 = 2,
// REBA trunk 1 + 1 = 2. Neck bent 20° sideways → RULA neck 1 + 1, REBA neck 1 + 1.
TEST(Rula, TwistAndSideBendAdjustments) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "lumbar.z", 15);
  f.set(q, "neck.x", 20);
  const Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.body.trunk_twist_deg, 15.0, 1e-9);
  EXPECT_NEAR(std::abs(a.angles.body.neck_side_bend_deg), 20.0, 1e-9);
  EXPECT_EQ(a.rula[L].trunk, 2);
  EXPECT_EQ(a.rula[L].neck, 2);
  EXPECT_EQ(a.reba[L].trunk, 2);
  EXPECT_EQ(a.reba[L].neck, 2);
}

// Arm abducted 85° from the trunk to the side with the shoulder raised 20° (the shoulder joint rides on the
// clavicle: 20° of elevation + 65° at the shoulder): elevation 85° → 3 (45–90°), abducted +1, raised +1 →
// upper arm 5; the straight arm puts the wrist ~0.55 m out to the side → lower arm 2 + 1 = 3; wrist 1,
// twist 1 → Table A[5][3][1][1] = 6 → C = 6, D = 1 → Table C[6][1] = 4 (action level 2).
TEST(Rula, AbductedRaisedArmOutToTheSide) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "shoulder_l.x", 65);
  f.set(q, "sternoclavicular_l", 20);
  const Assessment a = f.eval.evaluate(q);
  const ArmAngles& arm = a.angles.arm[L];
  EXPECT_NEAR(arm.upper_arm_abduction_deg, 85.0, 1e-9);
  EXPECT_NEAR(arm.upper_arm_flexion_deg, 85.0, 1e-9);
  EXPECT_NEAR(arm.shoulder_elevation_deg, 20.0, 1e-9);
  EXPECT_TRUE(arm.out_to_side);
  EXPECT_EQ(a.rula[L].upper_arm_base, 3);
  EXPECT_EQ(a.rula[L].upper_arm, 5);
  EXPECT_EQ(a.rula[L].lower_arm, 3);
  EXPECT_EQ(a.rula[L].posture_a, 6);
  EXPECT_EQ(a.rula[L].grand, 4);
  // arm supported: −1
  TaskInput in;
  in.arm_supported = true;
  EXPECT_EQ(f.eval.evaluate(q, in).rula[L].upper_arm, 4);
}

// Wrist: deviation (radial + on both sides, 15° > 10°) gives RULA wrist 1 + 1 = 2 and REBA wrist 1 + 1 = 2;
// forearm rotation near an end of its 0–160° range (150°) gives RULA twist 2 and REBA's wrist +1, the
// middle half (40–120°) twist 1. Upper arm extended 40°: RULA/REBA upper arm 2 (extension > 20°).
TEST(Rula, WristDeviationTwistAndArmExtension) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "wrist_deviation_l", 15);
  f.set(q, "wrist_deviation_r", 15);
  f.set(q, "shoulder_r.y", 40);  // extension is +y
  Assessment a = f.eval.evaluate(q);
  for (int s : {L, R}) {
    EXPECT_NEAR(a.angles.arm[s].wrist_deviation_deg, 15.0, 1e-9);
    EXPECT_NEAR(a.angles.arm[s].wrist_flexion_deg, 0.0, 1e-9);
    EXPECT_EQ(a.rula[s].wrist_base, 1);
    EXPECT_EQ(a.rula[s].wrist, 2);
    EXPECT_EQ(a.reba[s].wrist, 2);
  }
  EXPECT_NEAR(a.angles.arm[R].upper_arm_flexion_deg, -40.0, 1e-9);
  EXPECT_EQ(a.rula[R].upper_arm, 2);
  EXPECT_EQ(a.reba[R].upper_arm, 2);
  q = f.relaxed();
  f.set(q, "radioulnar_l", 150);
  f.set(q, "radioulnar_r", 110);
  a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.arm[L].forearm_rotation_deg, 150.0, 1e-9);
  EXPECT_EQ(a.rula[L].wrist_twist, 2);
  EXPECT_EQ(a.reba[L].wrist, 2);
  EXPECT_EQ(a.rula[R].wrist_twist, 1);
  EXPECT_EQ(a.reba[R].wrist, 1);
}

// Hand reaching across the body: shoulder flexed 45° and adducted 30°, elbow 90°: the wrist crosses the
// midsagittal plane → lower arm 1 + 1 = 2.
TEST(Rula, AcrossTheMidline) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "shoulder_l.y", -70);
  f.set(q, "shoulder_l.z", -70);  // internal rotation swings the flexed forearm across
  f.set(q, "elbow_l", 90);
  const Assessment a = f.eval.evaluate(q);
  EXPECT_LT(a.angles.arm[L].wrist_lateral_m, 0.0);
  EXPECT_TRUE(a.angles.arm[L].across_midline);
  EXPECT_EQ(a.rula[L].lower_arm_base, 1);
  EXPECT_EQ(a.rula[L].lower_arm, 2);
}

// Worked example (ours, hand-scored from the two sheets; the papers' own worked examples are photographs
// we cannot reconstruct as joint angles): reaching forward and down to a part on a low bench, 5 kg,
// repeated more than 4 times a minute, fair hand hold. Trunk flexed 45° (lumbar 20° + thoracic 25°),
// neck 15°, left shoulder flexed 60° (relative to the trunk), elbow 40°, wrist flexed 20°, forearm
// mid-rotation.
// RULA left: upper arm 45–90° → 3; lower arm 40° → 2; wrist > 15° → 3; twist 1 → Table A[3][2][3][1] = 4;
// muscle use 1 (repeated), force 5 kg repeated → 2; C = 4 + 1 + 2 = 7. Neck 10–20° → 2, trunk 20–60° → 3,
// legs 1 → Table B[2][3][1] = 4; D = 4 + 1 + 2 = 7. Table C[7][7] = 7: grand score 7, action level 4.
// REBA left: trunk 3, neck 0–20° → 1, legs 1 → Table A[3][1][1] = 2; load 5–10 kg → 1; A = 3. Upper arm 3,
// lower arm 2, wrist 2 → Table B[3][2][2] = 5; coupling fair → 1; B = 6. Table C[3][6] = 5; activity +1
// (repeated) → REBA 6, action level 2 (medium).
TEST(Rula, WorkedExampleReachingDownWithALoad) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  f.set(q, "lumbar.y", 20);
  f.set(q, "thoracic.y", 25);
  f.set(q, "neck.y", 15);
  f.set(q, "shoulder_l.y", -60);
  f.set(q, "elbow_l", 40);
  f.set(q, "wrist_l", 20);
  TaskInput in;
  in.load_kg = 5;
  in.repeated = true;
  in.coupling = Coupling::kFair;
  const Assessment a = f.eval.evaluate(q, in);
  EXPECT_NEAR(a.angles.body.trunk_flexion_deg, 45.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].upper_arm_flexion_deg, 60.0, 1e-9);
  EXPECT_NEAR(a.angles.arm[L].elbow_flexion_deg, 40.0, 1e-6);
  EXPECT_NEAR(a.angles.arm[L].wrist_flexion_deg, 20.0, 1e-9);
  const RulaSide& r = a.rula[L];
  EXPECT_EQ(r.upper_arm, 3);
  EXPECT_EQ(r.lower_arm, 2);
  EXPECT_EQ(r.wrist, 3);
  EXPECT_EQ(r.wrist_twist, 1);
  EXPECT_EQ(r.posture_a, 4);
  EXPECT_EQ(r.muscle_use, 1);
  EXPECT_EQ(r.force_load, 2);
  EXPECT_EQ(r.score_c, 7);
  EXPECT_EQ(r.neck, 2);
  EXPECT_EQ(r.trunk, 3);
  EXPECT_EQ(r.posture_b, 4);
  EXPECT_EQ(r.score_d, 7);
  EXPECT_EQ(r.grand, 7);
  EXPECT_EQ(r.action_level, 4);
  const RebaSide& b = a.reba[L];
  EXPECT_EQ(b.trunk, 3);
  EXPECT_EQ(b.neck, 1);
  EXPECT_EQ(b.legs, 1);
  EXPECT_EQ(b.table_a, 2);
  EXPECT_EQ(b.load, 1);
  EXPECT_EQ(b.score_a, 3);
  EXPECT_EQ(b.upper_arm, 3);
  EXPECT_EQ(b.lower_arm, 2);
  EXPECT_EQ(b.wrist, 2);
  EXPECT_EQ(b.table_b, 5);
  EXPECT_EQ(b.score_b, 6);
  EXPECT_EQ(b.table_c, 5);
  EXPECT_EQ(b.activity, 1);
  EXPECT_EQ(b.score, 6);
  EXPECT_EQ(b.action_level, 2);
}

// Squat: hips flexed 70°, knees 70° (trunk stays upright: the pelvis is not tilted). REBA legs 1 + 2
// (knees > 60°) = 3 → Table A[1][1][3] = 3; B = 1 → Table C[3][1] = 2. With 12 kg and a jerk: load
// 2 + 1 = 3 → A = 6 → Table C[6][1] = 6. RULA with 12 kg intermittent: force 2 → C = 2 + 2 = 4, D = 1 + 2
// = 3 → Table C[4][3] = 3; with a shock: force 3 → C = 5, D = 4 → Table C[5][4] = 5.
TEST(Reba, SquatKneesAndLoad) {
  Fixture f;
  sk::VectorX q = f.relaxed();
  for (const char* s : {"_l", "_r"}) {
    f.set(q, std::string("hip") + s + ".y", -70);
    f.set(q, std::string("knee") + s, 70);
  }
  Assessment a = f.eval.evaluate(q);
  EXPECT_NEAR(a.angles.body.knee_flexion_deg[L], 70.0, 1e-6);
  EXPECT_EQ(a.reba[L].legs, 3);
  EXPECT_EQ(a.reba[L].table_a, 3);
  EXPECT_EQ(a.reba[L].score, 2);
  TaskInput in;
  in.load_kg = 12;
  a = f.eval.evaluate(q, in);
  EXPECT_EQ(a.rula[L].force_load, 2);
  EXPECT_EQ(a.rula[L].grand, 3);
  in.shock = true;
  a = f.eval.evaluate(q, in);
  EXPECT_EQ(a.reba[L].load, 3);
  EXPECT_EQ(a.reba[L].score_a, 6);
  EXPECT_EQ(a.reba[L].score, 6);
  EXPECT_EQ(a.rula[L].force_load, 3);
  EXPECT_EQ(a.rula[L].grand, 5);
  // sitting: no knee adjustment
  in = TaskInput{};
  in.sitting = true;
  EXPECT_EQ(f.eval.evaluate(q, in).reba[L].legs, 1);
}

TEST(Scores, PartBandsAtTheirEdges) {
  EXPECT_EQ(rulaUpperArmBase(-20), 1);
  EXPECT_EQ(rulaUpperArmBase(-21), 2);
  EXPECT_EQ(rulaUpperArmBase(20), 1);
  EXPECT_EQ(rulaUpperArmBase(20.5), 2);
  EXPECT_EQ(rulaUpperArmBase(45), 2);
  EXPECT_EQ(rulaUpperArmBase(46), 3);
  EXPECT_EQ(rulaUpperArmBase(90), 3);
  EXPECT_EQ(rulaUpperArmBase(91), 4);
  EXPECT_EQ(rulaLowerArmBase(59), 2);
  EXPECT_EQ(rulaLowerArmBase(60), 1);
  EXPECT_EQ(rulaLowerArmBase(100), 1);
  EXPECT_EQ(rulaLowerArmBase(101), 2);
  EXPECT_EQ(rulaWristBase(0, 5), 1);
  EXPECT_EQ(rulaWristBase(-10, 5), 2);
  EXPECT_EQ(rulaWristBase(16, 5), 3);
  EXPECT_EQ(rulaNeckBase(10, 5), 1);
  EXPECT_EQ(rulaNeckBase(15, 5), 2);
  EXPECT_EQ(rulaNeckBase(21, 5), 3);
  EXPECT_EQ(rulaNeckBase(-6, 5), 4);
  EXPECT_EQ(rulaTrunkBase(0, 5), 1);
  EXPECT_EQ(rulaTrunkBase(10, 5), 2);
  EXPECT_EQ(rulaTrunkBase(30, 5), 3);
  EXPECT_EQ(rulaTrunkBase(61, 5), 4);
  EXPECT_EQ(rulaTrunkBase(20, 5), 2);
  EXPECT_EQ(rulaTrunkBase(21, 5), 3);
  EXPECT_EQ(rulaTrunkBase(60, 5), 3);
  EXPECT_EQ(rulaTrunkBase(-10, 5), 2);
  EXPECT_EQ(rulaNeckBase(20, 5), 2);
  EXPECT_EQ(rulaNeckBase(-5, 5), 1);
  EXPECT_EQ(rulaWristBase(15, 5), 2);
  EXPECT_EQ(rebaTrunkBase(20, 5), 2);
  EXPECT_EQ(rebaTrunkBase(21, 5), 3);
  EXPECT_EQ(rebaTrunkBase(60, 5), 3);
  EXPECT_EQ(rebaTrunkBase(-20, 5), 2);
  EXPECT_EQ(rebaKneeAdjustment(60), 1);
  EXPECT_EQ(rebaTrunkBase(0, 5), 1);
  EXPECT_EQ(rebaTrunkBase(-10, 5), 2);
  EXPECT_EQ(rebaTrunkBase(-25, 5), 3);
  EXPECT_EQ(rebaTrunkBase(61, 5), 4);
  EXPECT_EQ(rebaNeckBase(20, 5), 1);
  EXPECT_EQ(rebaNeckBase(21, 5), 2);
  EXPECT_EQ(rebaKneeAdjustment(29), 0);
  EXPECT_EQ(rebaKneeAdjustment(30), 1);
  EXPECT_EQ(rebaKneeAdjustment(61), 2);
  EXPECT_EQ(rebaWristBase(15), 1);
  EXPECT_EQ(rebaWristBase(-16), 2);
  EXPECT_EQ(rulaActionLevel(2), 1);
  EXPECT_EQ(rulaActionLevel(3), 2);
  EXPECT_EQ(rulaActionLevel(6), 3);
  EXPECT_EQ(rulaActionLevel(7), 4);
  EXPECT_EQ(rebaActionLevel(1), 0);
  EXPECT_EQ(rebaActionLevel(3), 1);
  EXPECT_EQ(rebaActionLevel(7), 2);
  EXPECT_EQ(rebaActionLevel(10), 3);
  EXPECT_EQ(rebaActionLevel(11), 4);
}

TEST(Scores, LoadAdjustments) {
  TaskInput in;
  EXPECT_EQ(rulaForceLoad(in), 0);
  in.load_kg = 1.9;
  EXPECT_EQ(rulaForceLoad(in), 0);
  in.load_kg = 2;
  EXPECT_EQ(rulaForceLoad(in), 1);  // 2–10 kg intermittent
  in.static_posture = true;
  EXPECT_EQ(rulaForceLoad(in), 2);  // 2–10 kg static
  EXPECT_EQ(rulaMuscleUse(in), 1);
  in.static_posture = false;
  in.repeated = true;
  in.load_kg = 9.9;
  EXPECT_EQ(rulaForceLoad(in), 2);  // 2–10 kg repeated
  in.load_kg = 10;
  EXPECT_EQ(rulaForceLoad(in), 3);  // ≥ 10 kg repeated
  in.repeated = false;
  EXPECT_EQ(rulaForceLoad(in), 2);  // ≥ 10 kg intermittent
  EXPECT_EQ(rulaMuscleUse(in), 0);
  in.load_kg = 0;
  in.shock = true;
  EXPECT_EQ(rulaForceLoad(in), 3);
  in = TaskInput{};
  in.load_kg = 4.9;
  EXPECT_EQ(rebaLoad(in), 0);
  in.load_kg = 5;
  EXPECT_EQ(rebaLoad(in), 1);
  in.load_kg = 10;
  EXPECT_EQ(rebaLoad(in), 1);
  in.load_kg = 10.5;
  EXPECT_EQ(rebaLoad(in), 2);
  in.shock = true;
  EXPECT_EQ(rebaLoad(in), 3);
  in.static_posture = in.repeated = in.rapid_large_changes = true;
  EXPECT_EQ(rebaActivity(in), 3);

  // on a posture: a heavier load never lowers the grand scores
  Fixture f;
  const sk::VectorX q = f.relaxed();
  int last_rula = 0, last_reba = 0;
  for (double kg : {0.0, 1.0, 3.0, 6.0, 11.0, 25.0}) {
    TaskInput t;
    t.load_kg = kg;
    t.static_posture = true;
    const Assessment a = f.eval.evaluate(q, t);
    EXPECT_GE(a.rula[L].grand, last_rula) << kg;
    EXPECT_GE(a.reba[L].score, last_reba) << kg;
    last_rula = a.rula[L].grand;
    last_reba = a.reba[L].score;
  }
  EXPECT_GT(last_rula, 2);
  EXPECT_GT(last_reba, 2);
}

// More flexion never lowers a part score, swept through the joints' ranges on the skeleton.
TEST(Scores, MoreFlexionNeverLowersAPartScore) {
  Fixture f;
  const auto sweep = [&](auto&& pose, double from, double to, auto&& score, const char* what) {
    int last = 0;
    for (double d = from; d <= to + 1e-9; d += 2.5) {
      sk::VectorX q = f.relaxed();
      pose(q, d);
      const int s = score(f.eval.evaluate(q));
      EXPECT_GE(s, last) << what << " at " << d << " deg";
      last = s;
    }
    return last;
  };
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "shoulder_l.y", -d); }, 0, 170,
                  [](const Assessment& a) { return a.rula[L].upper_arm; }, "upper arm (RULA)"),
            4);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "shoulder_l.y", -d); }, 0, 170,
                  [](const Assessment& a) { return a.reba[L].upper_arm; }, "upper arm (REBA)"),
            4);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "lumbar.y", d / 2); f.set(q, "thoracic.y", d / 2); },
                  0, 80, [](const Assessment& a) { return a.rula[L].trunk; }, "trunk (RULA)"),
            4);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "lumbar.y", d / 2); f.set(q, "thoracic.y", d / 2); },
                  0, 80, [](const Assessment& a) { return a.reba[L].trunk; }, "trunk (REBA)"),
            4);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "neck.y", d); }, 0, 45,
                  [](const Assessment& a) { return a.rula[L].neck; }, "neck (RULA)"),
            3);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "wrist_l", d); }, 0, 80,
                  [](const Assessment& a) { return a.rula[L].wrist; }, "wrist flexion (RULA)"),
            3);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "wrist_l", -d); }, 0, 70,
                  [](const Assessment& a) { return a.reba[L].wrist; }, "wrist extension (REBA)"),
            2);
  EXPECT_EQ(sweep([&](sk::VectorX& q, double d) { f.set(q, "knee_r", d); }, 0, 135,
                  [](const Assessment& a) { return a.reba[L].legs; }, "knee (REBA legs)"),
            3);
  // and the grand scores do not drop as the trunk bends further
  sweep([&](sk::VectorX& q, double d) { f.set(q, "lumbar.y", d / 2); f.set(q, "thoracic.y", d / 2); }, 0, 80,
        [](const Assessment& a) { return a.rula[L].grand; }, "RULA grand");
  sweep([&](sk::VectorX& q, double d) { f.set(q, "lumbar.y", d / 2); f.set(q, "thoracic.y", d / 2); }, 0, 80,
        [](const Assessment& a) { return a.reba[L].score; }, "REBA score");
}

TEST(JointLimits, FractionOfTheRangeUsedAndTheWorstJoint) {
  Fixture f;
  sk::VectorX q = f.standing();
  JointLimitReport rep = f.eval.jointLimits(q);
  ASSERT_GE(rep.worst, 0);
  EXPECT_NEAR(rep.joints[rep.worst].fraction, 0.0, 1e-12);  // the anatomical posture uses no range
  f.set(q, "elbow_l", 120);       // 120 of 150°
  f.set(q, "shoulder_r.y", -85);  // half of the 170° flexion
  rep = f.eval.jointLimits(q);
  EXPECT_EQ(rep.joints[rep.worst].joint, "elbow_l");
  EXPECT_NEAR(rep.joints[rep.worst].fraction, 0.8, 1e-12);
  for (const JointLimitUse& u : rep.joints) {
    if (u.joint == "shoulder_r") { EXPECT_NEAR(u.fraction, 0.5, 1e-12); }
    EXPECT_NE(u.joint, "root");  // no limits on the free flyer
  }
  f.set(q, "knee_l", 150);  // past the 135° limit
  rep = f.eval.jointLimits(q);
  EXPECT_EQ(rep.joints[rep.worst].joint, "knee_l");
  EXPECT_NEAR(rep.joints[rep.worst].fraction, 150.0 / 135.0, 1e-12);
}

// Arm length of the 1.75 m male from de Leva's lengths scaled by 1.75/1.741: upper arm 0.2817, forearm
// 0.2689, and the palm point (0.02, 0, −0.45 hand) from the wrist, hand = 0.108 × 1.75.
TEST(Reach, DistanceFromTheShoulderAgainstTheArmLength) {
  Fixture f;
  const double k = 1.75 / 1.741;
  const double expected = (0.2817 + 0.2689) * k + std::hypot(0.02, 0.45 * 0.108 * 1.75);
  EXPECT_NEAR(f.eval.armLength(Side::kLeft), expected, 1e-9);
  EXPECT_NEAR(f.eval.armLength(Side::kRight), expected, 1e-9);

  sk::VectorX q = f.standing();
  f.set(q, "lumbar.y", 20);  // the shoulder moves with the trunk
  sk::Data data(f.model);
  sk::forwardKinematics(f.model, data, q);
  const sk::Vector3 shoulder = data.oMi[f.model.jointIndex("shoulder_l")].p;
  const sk::Vector3 dir = sk::Vector3(1, 0.3, 0.2).normalized();
  const sk::Vector3 far = shoulder + (expected + 0.25) * dir;
  ReachResult r = f.eval.reach(q, Side::kLeft, far);
  EXPECT_FALSE(r.reachable);
  EXPECT_NEAR(r.miss, 0.25, 1e-9);
  EXPECT_NEAR((r.shoulder - shoulder).norm(), 0.0, 1e-12);
  r = f.eval.reach(q, Side::kLeft, shoulder + 0.5 * dir);
  EXPECT_TRUE(r.reachable);
  EXPECT_EQ(r.miss, 0.0);
  // the palm of the posture itself is always within reach
  const sk::Vector3 palm = data.oMf[f.model.frameIndex("palm_l")].p;
  r = f.eval.reach(q, Side::kLeft, palm);
  EXPECT_TRUE(r.reachable);
  EXPECT_LE(r.distance, r.arm_length);
}

// Scoring from the caller's kinematics (the sim's data after a step) gives what scoring from q gives,
// angle for angle, and refuses a data of another model or a non-finite pose.
TEST(Evaluator, FromTheCallersKinematicsAsFromQ) {
  Fixture f;
  const sk::VectorX q0 = f.standing();
  sk::Data d(f.model);
  for (int k = 0; k < 8; ++k) {
    sk::VectorX q = q0;
    for (int j = 6; j < f.model.nq; ++j) {
      const double lo = f.model.lower_limit[j], hi = f.model.upper_limit[j];
      if (std::isfinite(lo) && std::isfinite(hi)) q[j] = q0[j] + (k / 8.0) * 0.6 * (0.5 * (lo + hi) - q0[j]);
    }
    sk::forwardKinematics(f.model, d, q);
    const Assessment a = f.eval.evaluate(q), b = f.eval.evaluate(d);
    EXPECT_EQ(a.angles.body.trunk_flexion_deg, b.angles.body.trunk_flexion_deg) << k;
    EXPECT_EQ(a.angles.arm[0].upper_arm_flexion_deg, b.angles.arm[0].upper_arm_flexion_deg) << k;
    EXPECT_EQ(a.angles.arm[1].wrist_deviation_deg, b.angles.arm[1].wrist_deviation_deg) << k;
    EXPECT_EQ(a.angles.body.neck_twist_deg, b.angles.body.neck_twist_deg) << k;
    for (int s = 0; s < 2; ++s) {
      EXPECT_EQ(a.rula[s].grand, b.rula[s].grand) << k;
      EXPECT_EQ(a.reba[s].score, b.reba[s].score) << k;
    }
  }
  sk::Data bad = d;
  bad.oMi[3].p.x() = std::nan("");
  try {
    f.eval.evaluate(bad);
    ADD_FAILURE() << "no error for a NaN joint pose";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is not finite"), std::string::npos) << e.what();
  }
  bad = d;
  bad.oMf.pop_back();
  EXPECT_THROW(f.eval.evaluate(bad), std::invalid_argument);
}

TEST(BadInput, ClearErrors) {
  Fixture f;
  sk::VectorX q = f.standing();
  const auto message = [](auto&& fn) {
    try {
      fn();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  sk::VectorX bad = q;
  bad(f.model.joints[f.model.jointIndex("elbow_l")].idx_q) = std::nan("");
  EXPECT_NE(message([&] { f.eval.evaluate(bad); }).find("'elbow_l' is not finite"), std::string::npos);
  EXPECT_NE(message([&] { f.eval.evaluate(sk::VectorX::Zero(5)); }).find("q has 5 coordinates"),
            std::string::npos);
  TaskInput in;
  in.load_kg = -3;
  EXPECT_NE(message([&] { f.eval.evaluate(q, in); }).find("load_kg = -3"), std::string::npos);
  in.load_kg = std::nan("");
  EXPECT_NE(message([&] { f.eval.evaluate(q, in); }).find("load_kg is not finite"), std::string::npos);
  EXPECT_NE(message([&] { f.eval.reach(q, Side::kLeft, sk::Vector3(0, std::nan(""), 0)); }).find("not finite"),
            std::string::npos);
  EXPECT_NE(message([&] { f.eval.jointLimits(bad); }).find("elbow_l"), std::string::npos);
  Thresholds t;
  t.neutral_deg = -1;
  EXPECT_NE(message([&] { Evaluator e(f.model, t); }).find("neutral_deg"), std::string::npos);
  sk::Model tiny;
  tiny.name = "tiny";
  tiny.addJoint("root", sk::JointType::kFreeFlyer, -1, sk::SE3::Identity());
  EXPECT_NE(message([&] { Evaluator e(tiny); }).find("has no joint 'thoracic'"), std::string::npos);
  // angles a caller built: a NaN angle, a bad neutral band or side are errors, not the worst band
  PostureAngles angles = f.eval.measure(q);
  angles.body.trunk_flexion_deg = std::nan("");
  EXPECT_NE(message([&] { scoreRula(angles, Side::kLeft, {}); }).find("trunk_flexion_deg is not finite"), std::string::npos);
  angles = f.eval.measure(q);
  angles.arm[1].wrist_flexion_deg = std::numeric_limits<double>::infinity();
  EXPECT_NE(message([&] { scoreReba(angles, Side::kRight, {}); }).find("wrist_flexion_deg is not finite"), std::string::npos);
  EXPECT_NO_THROW(scoreReba(angles, Side::kLeft, {}));  // the left arm's angles are fine
  angles = f.eval.measure(q);
  angles.neutral_deg = std::nan("");
  EXPECT_NE(message([&] { scoreRula(angles, Side::kLeft, {}); }).find("neutral_deg"), std::string::npos);
  angles = f.eval.measure(q);
  EXPECT_NE(message([&] { scoreRula(angles, static_cast<Side>(7), {}); }).find("side must be left or right"), std::string::npos);
}
