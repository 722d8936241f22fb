#include "mannequin/skeleton/bvh_drive.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin::skeleton;
using mannequin::core::ConfigError;

namespace {
std::string repo(const std::string& rel) {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + rel;
}

struct Drive {
  Model model;
  BvhDriveMap map;
  Bvh bvh;
  Drive(const std::string& mannequin, const std::string& mapping, const std::string& capture)
      : model(buildMannequin(loadMannequinSpec(repo(mannequin)))), map(loadBvhDriveMap(repo(mapping))) {
    BvhReadOptions o;
    o.unit_scale_to_m = map.unit_scale_to_m;
    bvh = readBvhFile(repo(capture), o);
  }
};
}  // namespace

TEST(BvhDrive, CmuCaptureDrivesTheMannequinWithinLimits) {
  Drive d("configs/mannequins/male_50th.yaml", "configs/mappings/cmu.yaml", "data/bvh/cmu_max_131_03.bvh");
  BvhDriver driver(d.model, d.bvh, d.map);
  const auto names = driver.segmentNames();
  ASSERT_EQ(names.front(), "pelvis");
  double mean = 0;
  std::vector<double> seg(names.size(), 0.0);
  for (int f = 0; f < d.bvh.num_frames; f += 10) {
    const BvhDriveFrame r = driver.drive(f);
    ASSERT_TRUE(r.q.allFinite());
    EXPECT_TRUE(((r.q - d.model.lower_limit).array() >= -1e-12).all()) << "frame " << f;
    EXPECT_TRUE(((d.model.upper_limit - r.q).array() >= -1e-12).all()) << "frame " << f;
    mean += r.mean_error_deg;
    for (size_t k = 0; k < seg.size(); ++k) seg[k] = std::max(seg[k], r.error_deg[k]);
  }
  mean /= (d.bvh.num_frames + 9) / 10;
  // ball joints reproduce orientations exactly unless a limit binds; revolute chains are projections
  EXPECT_LT(mean, 10.0);
  for (const char* exact : {"pelvis", "abdomen", "head", "thigh_l", "shank_r"}) {
    const size_t k = std::find(names.begin(), names.end(), exact) - names.begin();
    EXPECT_LT(seg[k], 8.0) << exact;
  }
  // the mannequin stands about as tall as the actor scaled to it
  EXPECT_GT(driver.scale(), 0.9);
  EXPECT_LT(driver.scale(), 1.2);
}

TEST(BvhDrive, MocapbankSitDownLowersThePelvis) {
  Drive d("configs/mannequins/female_05th.yaml", "configs/mappings/mocapbank.yaml", "data/bvh/mocapbank_test.bvh");
  BvhDriver driver(d.model, d.bvh, d.map);
  Data data(d.model);
  double lo = 1e9, hi = -1e9;
  for (int f = 0; f < d.bvh.num_frames; f += 5) {
    forwardKinematics(d.model, data, driver.drive(f).q);
    lo = std::min(lo, data.oMi[0].p.z());
    hi = std::max(hi, data.oMi[0].p.z());
  }
  // the actor's pelvis goes from ~94 cm to ~47 cm: half its height, scaled to the 5th-percentile female
  EXPECT_GT(hi - lo, 0.3 * hi);
  EXPECT_LT(hi - lo, 0.7 * hi);
}

TEST(BvhDrive, BadMappingsAreReportedWithNames) {
  Drive d("configs/mannequins/male_50th.yaml", "configs/mappings/cmu.yaml", "data/bvh/cmu_max_131_03.bvh");
  BvhDriveMap bad = d.map;
  bad.segments[3].second = "Noggin";
  try {
    BvhDriver driver(d.model, d.bvh, bad);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("BVH joint 'Noggin'"), std::string::npos) << e.what();
  }
  bad = d.map;
  bad.segments[2].first = "torso";
  EXPECT_THROW(BvhDriver(d.model, d.bvh, bad), std::invalid_argument);
  bad = d.map;
  std::swap(bad.segments[0], bad.segments[1]);  // root must come first
  EXPECT_THROW(BvhDriver(d.model, d.bvh, bad), std::invalid_argument);
  BvhDriver ok(d.model, d.bvh, d.map);
  EXPECT_THROW(ok.drive(d.bvh.num_frames), std::out_of_range);

  const auto error = [](const std::string& yaml) {
    try {
      parseBvhDriveMap(yaml, "map.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto expectError = [&](const std::string& yaml, const std::string& what) {
    const std::string e = error(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "yaml:\n" << yaml << "got: " << e;
  };
  expectError("name: x\nunit: furlong\nsegments:\n  pelvis: Hips\n",
              "map.yaml:2: field 'unit': expected m, cm, inch or cmu, got 'furlong'");
  expectError("name: x\nsegmentz: 1\n", "map.yaml:2: field 'segmentz': unknown key");
  expectError("name: x\n", "map.yaml:1: field '<top>': missing required key 'segments'");
  expectError("name: x\nsegments: {}\n", "map.yaml:2: field 'segments': expected a map of mannequin segments to BVH joints");
  expectError("segments:\n  pelvis: [a, b]\n", "map.yaml:2: field 'segments.pelvis': must name one BVH joint");
  expectError("unit: cm\nscale_to_m: 0.01\nsegments:\n  pelvis: Hips\n", "map.yaml:2: field 'scale_to_m': give either");
  expectError("scale_to_m: 0\nsegments:\n  pelvis: Hips\n", "map.yaml:1: field 'scale_to_m': must be > 0");
  try {
    loadBvhDriveMap("/nonexistent/map.yaml");
    ADD_FAILURE() << "no error for a missing mapping file";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/map.yaml:0: cannot read the file", 0), 0u) << e.what();
  }
}
