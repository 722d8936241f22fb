// Retargeting a real capture onto mannequins of other sizes, and the BVH writer (the tool: retarget_tool_test.cpp).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "mannequin/ik/retarget.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/bvh_write.hpp"
#include "../common/source.hpp"

namespace mannequin::ik {
namespace {

using mannequin::testing::sourceDir;
Model mannequin(const std::string& name) {
  return skeleton::buildMannequin(skeleton::loadMannequinSpec(sourceDir() + "/configs/mannequins/" + name + ".yaml"));
}
skeleton::Bvh cmu(const skeleton::BvhDriveMap& map) {
  skeleton::BvhReadOptions o;
  o.unit_scale_to_m = map.unit_scale_to_m;
  return skeleton::readBvhFile(sourceDir() + "/data/bvh/cmu_max_131_03.bvh", o);
}

TEST(BvhWriter, WrittenMotionReadsBackWithTheSameJointPositions) {
  const Model m = mannequin("male_50th");
  std::vector<VectorX> frames;
  std::srand(3);
  for (int f = 0; f < 4; ++f) {
    VectorX q = skeleton::clampToLimits(m, VectorX::Random(m.nq));
    q.head<3>() = Vector3(0.3 * f, -0.2, 0.9);
    frames.push_back(q);
  }
  std::ostringstream out;
  skeleton::writeMannequinBvh(out, m, frames, 1.0 / 120);
  const skeleton::Bvh bvh = skeleton::parseBvh(out.str(), "written.bvh");
  ASSERT_EQ(bvh.num_frames, 4);
  EXPECT_NEAR(bvh.frame_time, 1.0 / 120, 1e-8);
  const Matrix3 C = skeleton::mannequinToBvhAxes();
  Data data(m);
  for (int f = 0; f < 4; ++f) {
    skeleton::forwardKinematics(m, data, frames[f]);
    const auto world = skeleton::bvhWorldPoses(bvh, f);  // file units: cm
    for (std::size_t j = 0; j < m.joints.size(); ++j) {
      const int b = skeleton::findBvhJoint(bvh, m.joints[j].name);
      ASSERT_GE(b, 0) << m.joints[j].name;
      EXPECT_LT((world[b].p - 100.0 * C * data.oMi[j].p).norm(), 1e-3) << m.joints[j].name << " frame " << f;
      EXPECT_LT((world[b].R - C * data.oMi[j].R * C.transpose()).norm(), 1e-6) << m.joints[j].name;
    }
  }
  VectorX bad = frames[0];
  bad(7) = std::numeric_limits<double>::quiet_NaN();
  std::ostringstream sink;
  EXPECT_THROW(skeleton::writeMannequinBvh(sink, m, {bad}, 0.01), std::invalid_argument);
  EXPECT_THROW(skeleton::writeMannequinBvh(sink, m, frames, 0.0), std::invalid_argument);
}

TEST(Retarget, SmallAndTallMannequinsKeepFeetFirstThenPelvisThenHands) {
  const auto map = skeleton::loadBvhDriveMap(sourceDir() + "/configs/mappings/cmu.yaml");
  const skeleton::Bvh bvh = cmu(map);
  for (const char* name : {"female_05th", "male_95th"}) {
    const Model m = mannequin(name);
    Retargeter r(m, bvh, map);
    double feet = 0, feet_max = 0, pelvis = 0, hands = 0;
    int frames = 0, feet_ok = 0;
    for (long long f = 0; f < 150; ++f, ++frames) {
      const RetargetFrame out = r.solve(f);
      if (f == 0) {
        // calibration frame: every target met by construction
        for (int k = 0; k < 3; ++k) EXPECT_LT(out.report.levels[k].residual, 1e-6) << name << " level " << k;
      }
      feet += out.report.levels[0].residual;
      feet_max = std::max(feet_max, out.report.levels[0].residual);
      feet_ok += out.report.levels[0].satisfied;
      pelvis += out.report.levels[1].residual;
      hands += out.report.levels[2].residual;
      for (int i = 6; i < m.nq; ++i) {
        ASSERT_GE(out.q(i), m.lower_limit(i) - 1e-9) << name << " frame " << f;
        ASSERT_LE(out.q(i), m.upper_limit(i) + 1e-9) << name << " frame " << f;
      }
    }
    std::printf("%s: feet residual mean %.5f max %.5f (%d/%d frames satisfied), pelvis mean %.5f, hands mean %.5f\n",
                name, feet / frames, feet_max, feet_ok, frames, pelvis / frames, hands / frames);
    // the feet (top level) are met on most frames; the priority order shows in the residuals
    EXPECT_GE(feet_ok, frames * 85 / 100) << name;
    EXPECT_LT(feet / frames, 0.02) << name;
    EXPECT_LT(feet, pelvis) << name;
    EXPECT_LT(feet, hands) << name;
  }
}

TEST(Retarget, RejectsAMapWithoutTheControlledSegments) {
  const auto map = skeleton::loadBvhDriveMap(sourceDir() + "/configs/mappings/cmu.yaml");
  const skeleton::Bvh bvh = cmu(map);
  auto partial = map;
  partial.segments.erase(std::remove_if(partial.segments.begin(), partial.segments.end(),
                                        [](const auto& s) { return s.first == "hand_r"; }),
                         partial.segments.end());
  const Model m = mannequin("male_50th");
  try {
    Retargeter r(m, bvh, partial);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("hand_r"), std::string::npos) << e.what();
  }
  RetargetOptions o;
  o.calibration = "tpose";
  EXPECT_THROW(Retargeter(m, bvh, map, o), std::invalid_argument);
}

}  // namespace
}  // namespace mannequin::ik
