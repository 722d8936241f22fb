// C3dSource: rigid bodies fitted to marker clusters (a synthetic rigid cluster with known poses and
// gaps, written by the test-only writer; the c3d.org sample with configs/mappings/c3d_sample01.yaml),
// occlusion, and mapping errors naming FILE:LINE.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "c3d_writer.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/mocap/c3d_source.hpp"

#include "samples.hpp"
namespace fs = std::filesystem;
namespace mc = mannequin::mocap;
using mannequin::math::Matrix3;
using mannequin::math::SE3;
using mannequin::math::Vector3;

namespace {
using c3dtest::samplePath;
using c3dtest::sourceDir;

class TempDir {
 public:
  TempDir() : dir_(fs::temp_directory_path() / ("c3d_source_test_" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
  }
  ~TempDir() { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return (dir_ / name).string();
  }

 private:
  fs::path dir_;
};

// the true motion of the synthetic cluster: marker k at R(f) m_k + p(f), in mm
Matrix3 trueR(int f) {
  return (Eigen::AngleAxisd(0.05 * f, Vector3(0.3, -0.5, 0.8).normalized()) *
          Eigen::AngleAxisd(0.4, Vector3::UnitX()))
      .toRotationMatrix();
}
Vector3 trueP(int f) { return Vector3(100.0 + 7.0 * f, -50.0 + 3.0 * f, 900.0 - 2.0 * f); }
const Vector3 kMarkers[4] = {{60, 0, 0}, {0, 80, 0}, {-40, -30, 10}, {10, 20, 70}};

// frames 0..9; frame 0: two markers missing (occluded, never seen yet), frame 1 all four (the
// reference), frames 2-3: D missing (3 left: tracked), frame 4: C and D missing (occluded)
bool visible(int f, int k) {
  if (f == 0) return k < 2;
  if (f == 2 || f == 3) return k != 3;
  if (f == 4) return k < 2;
  return true;
}

std::string syntheticFile() {
  c3dtest::WriteSpec w;
  w.float_storage = true;
  w.scale = 0.1;
  w.rate = 100.0;
  w.labels = {"A", "B", "C", "D", "X"};
  for (int f = 0; f < 10; ++f) {
    std::vector<c3dtest::Marker> frame;
    for (int k = 0; k < 4; ++k) {
      const Vector3 x = trueR(f) * kMarkers[k] + trueP(f);
      frame.push_back({float(x.x()), float(x.y()), float(x.z()), visible(f, k), 0.5f});
    }
    frame.push_back({0, 0, 0, true, 0});  // X: not in the cluster
    w.frames.push_back(frame);
  }
  return c3dtest::writeC3d(w);
}

// the pose the source must give at frame f: identity axes and the markers' centroid at frame 1
SE3 expectedPose(int f) {
  const int r = 1;
  Vector3 c = Vector3::Zero();
  for (const Vector3& m : kMarkers) c += trueR(r) * m + trueP(r);
  c /= 4.0;
  SE3 pose;
  pose.R = trueR(f) * trueR(r).transpose();
  pose.p = (pose.R * (c - trueP(r)) + trueP(f)) * 0.001;
  return pose;
}

void expectPose(const SE3& a, const SE3& b, const std::string& what) {
  // float storage: 6e-8 relative on ~1 m coordinates, over a 0.1 m marker spread
  EXPECT_LT((a.p - b.p).norm(), 1e-6) << what;
  EXPECT_LT((a.R - b.R).norm(), 1e-5) << what;
}

mc::C3dMapping clusterMapping() {
  return mc::parseC3dMapping("name: synthetic\nmarkers:\n  box: [A, B, C, D]\n", "synthetic.yaml");
}

}  // namespace

TEST(C3dSource, RigidClusterPosesAndGaps) {
  TempDir tmp;
  mc::C3dSourceOptions o;
  o.file = tmp.write("rigid.c3d", syntheticFile());
  o.mapping = clusterMapping();
  o.paced = false;
  mc::C3dSource src(o);
  EXPECT_EQ(src.kind(), "c3d");
  ASSERT_EQ(src.referenceFrames(), std::vector<int>{1});
  std::vector<mc::Frame> frames;
  while (auto f = src.next(std::chrono::microseconds(0))) frames.push_back(*f);
  EXPECT_TRUE(src.finished());
  ASSERT_EQ(frames.size(), 10u);
  for (int f = 0; f < 10; ++f) {
    const mc::Frame& fr = frames[static_cast<std::size_t>(f)];
    SCOPED_TRACE(f);
    ASSERT_EQ(fr.bodies.size(), 1u);
    const mc::Body& b = fr.bodies[0];
    EXPECT_EQ(b.name, "box");
    EXPECT_EQ(fr.frame_number, static_cast<std::uint64_t>(f));
    EXPECT_EQ(fr.stamp_ns, f * 10'000'000LL);  // 100 Hz
    EXPECT_EQ(fr.calibration_pose, f == 0);
    if (f == 0) {  // occluded before it was ever seen: identity
      EXPECT_FALSE(b.tracked);
      expectPose(b.pose, SE3::Identity(), "frame 0");
    } else if (f == 4) {  // occluded: the last tracked pose (frame 3)
      EXPECT_FALSE(b.tracked);
      EXPECT_EQ(b.quality, 0.0);
      expectPose(b.pose, expectedPose(3), "frame 4");
    } else {
      EXPECT_TRUE(b.tracked);
      EXPECT_DOUBLE_EQ(b.quality, (f == 2 || f == 3) ? 0.75 : 1.0);
      expectPose(b.pose, expectedPose(f), "frame " + std::to_string(f));
    }
    // frameAt (no state) gives the same frame
    const mc::Frame again = src.frameAt(f, 0);
    EXPECT_EQ(again.bodies[0].tracked, b.tracked);
    EXPECT_LT((again.bodies[0].pose.p - b.pose.p).norm(), 1e-12);
    EXPECT_LT((again.bodies[0].pose.R - b.pose.R).norm(), 1e-12);
  }
}

TEST(C3dSource, MappingErrorsNameTheFileAndLine) {
  TempDir tmp;
  mc::C3dSourceOptions o;
  o.file = tmp.write("rigid.c3d", syntheticFile());
  o.paced = false;
  o.mapping = mc::parseC3dMapping("name: m\nmarkers:\n  box: [A, B, C]\n  arm: [A, B, NOPE]\n", "m.yaml");
  try {
    mc::C3dSource src(o);
    ADD_FAILURE() << "no error";
  } catch (const mannequin::core::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("m.yaml:4"), std::string::npos) << w;
    EXPECT_NE(w.find("marker 'NOPE' is not in " + o.file), std::string::npos) << w;
  }
  EXPECT_THROW(mc::parseC3dMapping("markers:\n  box: [A, B]\n", "m.yaml"), mannequin::core::ConfigError);
  EXPECT_THROW(mc::parseC3dMapping("markers:\n  box: [A, B, A]\n", "m.yaml"), mannequin::core::ConfigError);
  EXPECT_THROW(mc::parseC3dMapping("markers:\n  box: [A, B, C]\nunit: furlong\n", "m.yaml"),
               mannequin::core::ConfigError);
  EXPECT_THROW(mc::parseC3dMapping("markers:\n  box: [A, B, C]\nsegments: {}\n", "m.yaml"),
               mannequin::core::ConfigError);
  // a cluster whose markers are collinear in every frame has no orientation
  c3dtest::WriteSpec w;
  w.float_storage = true;
  w.labels = {"A", "B", "C"};
  w.frames = {{{0, 0, 0, true, 0}, {10, 0, 0, true, 0}, {20, 0, 0, true, 0}}};
  o.file = tmp.write("line.c3d", c3dtest::writeC3d(w));
  o.mapping = mc::parseC3dMapping("markers:\n  box: [A, B, C]\n", "m.yaml");
  EXPECT_THROW(mc::C3dSource{o}, std::invalid_argument);
}

TEST(C3dSource, SampleCaptureWithTheShippedMapping) {
  const mc::C3dMapping map = mc::loadC3dMapping(sourceDir() + "/configs/mappings/c3d_sample01.yaml");
  ASSERT_EQ(map.bodies.size(), 7u);
  std::vector<std::vector<mc::Frame>> runs;
  for (const char* kind : {"pr", "sr", "vr"}) {
    mc::C3dSourceOptions o;
    o.file = samplePath(kind);
    o.mapping = map;
    o.paced = false;
    mc::C3dSource src(o);
    std::vector<mc::Frame> frames;
    while (auto f = src.next(std::chrono::microseconds(0))) frames.push_back(*f);
    ASSERT_EQ(frames.size(), 450u);
    EXPECT_EQ(frames[449].stamp_ns, 449 * 20'000'000LL);  // 50 Hz
    // tracked only where at least 3 of the body's markers are valid
    const mc::C3d& c = src.c3d();
    int rejected = 0;
    for (std::size_t b = 0; b < map.bodies.size(); ++b) {
      for (int f = 0; f < 450; ++f) {
        int valid = 0;
        for (const std::string& m : map.bodies[b].markers) valid += c.point(f, c.pointIndex(m)).has_value() ? 1 : 0;
        const bool tracked = frames[static_cast<std::size_t>(f)].bodies[b].tracked;
        if (tracked) {
          ASSERT_GE(valid, 3) << map.bodies[b].body << " " << f;
        } else if (valid >= 3) {
          ++rejected;  // a marker off the body among three
        }
        if (!tracked && f > 0) {
          // occluded: the previous frame's pose held
          EXPECT_EQ(frames[static_cast<std::size_t>(f)].bodies[b].pose.p, frames[static_cast<std::size_t>(f) - 1].bodies[b].pose.p);
        }
      }
    }
    std::printf("%s: %d body-frames with 3+ markers visible but one off the body (occluded)\n", kind, rejected);
    runs.push_back(std::move(frames));
  }
  // the three processor formats give the same bodies
  for (std::size_t r = 1; r < runs.size(); ++r) {
    for (std::size_t f = 0; f < 450; ++f) {
      for (std::size_t b = 0; b < 7; ++b) {
        EXPECT_LT((runs[r][f].bodies[b].pose.p - runs[0][f].bodies[b].pose.p).norm(), 1e-9);
        EXPECT_LT((runs[r][f].bodies[b].pose.R - runs[0][f].bodies[b].pose.R).norm(), 1e-9);
      }
    }
  }
}

// Every tracked pose carries the body's markers from its reference frame onto the markers visible
// now: the markers a fit used lie within max_marker_error_m of where the pose puts them, and
// typically (median frame) within 5 mm (skin moves under the markers by millimetres while walking; a
// wrong fit, rotation transposed or markers mixed up, misses by the cluster's size, 5-40 cm).
TEST(C3dSource, SampleCaptureFitsCarryTheMarkers) {
  const mc::C3dMapping map = mc::loadC3dMapping(sourceDir() + "/configs/mappings/c3d_sample01.yaml");
  mc::C3dSourceOptions o;
  o.file = samplePath("pr");
  o.mapping = map;
  o.paced = false;
  mc::C3dSource src(o);
  const mc::C3d& c = src.c3d();
  auto marker = [&](int f, const std::string& label) {
    const auto p = c.point(f, c.pointIndex(label));
    return p ? std::optional<Vector3>(Vector3((*p)[0], (*p)[1], (*p)[2]) * 0.001) : std::nullopt;
  };
  for (std::size_t b = 0; b < map.bodies.size(); ++b) {
    SCOPED_TRACE(map.bodies[b].body);
    const int ref = src.referenceFrames()[b];
    SE3 at_ref;
    int used = 0;
    ASSERT_TRUE(src.fit(ref, b, at_ref, used));
    // at the reference frame: lab axes, the origin at the visible markers' centroid
    EXPECT_LT((at_ref.R - Matrix3::Identity()).norm(), 1e-9);
    Vector3 centroid = Vector3::Zero();
    for (const std::string& m : map.bodies[b].markers) {
      if (const auto x = marker(ref, m)) centroid += *x;
    }
    EXPECT_LT((at_ref.p - centroid / used).norm(), 1e-9);
    int tracked = 0, first = -1, last = -1;
    std::vector<double> rms_all;
    for (int f = 0; f < c.frames_present; ++f) {
      SE3 pose;
      if (!src.fit(f, b, pose, used)) continue;
      ++tracked;
      if (first < 0) first = f;
      last = f;
      double sum = 0.0;
      int n = 0;
      for (const std::string& m : map.bodies[b].markers) {
        const auto now = marker(f, m);
        const auto then = marker(ref, m);
        if (!now || !then) continue;
        const double e = (pose.R * (*then - at_ref.p) + pose.p - *now).norm();
        if (e > o.max_marker_error_m) continue;  // dropped as a gap
        sum += e * e;
        ++n;
      }
      ASSERT_GE(n, used) << "frame " << f;  // the markers the fit used are on the body
      rms_all.push_back(std::sqrt(sum / n));
    }
    std::sort(rms_all.begin(), rms_all.end());
    const double median = rms_all[rms_all.size() / 2];
    EXPECT_LT(median, 0.005);
    EXPECT_GT(tracked, 400);
    // the walk goes along +y in the lab frame (the markers' y from ~0.1 m to ~2.2 m over the 9 s, read
    // with mannequin-c3d points), at a constant height
    SE3 a, z;
    ASSERT_TRUE(src.fit(first, b, a, used));
    ASSERT_TRUE(src.fit(last, b, z, used));
    EXPECT_GT(z.p.y() - a.p.y(), 1.5);
    EXPECT_LT(std::abs(z.p.z() - a.p.z()), 0.1);
    std::printf("%-8s reference frame %3d, tracked %3d/450, RMS misfit of the markers used: median %.1f mm, "
                "90%% %.1f mm, worst %.1f mm\n",
                map.bodies[b].body.c_str(), ref, tracked, 1000 * median, 1000 * rms_all[rms_all.size() * 9 / 10],
                1000 * rms_all.back());
  }
}
