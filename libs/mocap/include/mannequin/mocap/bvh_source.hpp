#pragma once
/// \file bvh_source.hpp
/// \brief A BVH capture played as a tracker: the world poses of chosen joints (forward kinematics of
/// the file, in metres), turned from the BVH frame (y up, actor facing +z) into the room frame
/// (z up, facing +x: x_room = z_bvh, y_room = x_bvh, z_room = y_bvh), published as rigid bodies.
#include <string>
#include <utility>
#include <vector>

#include "mannequin/mocap/source.hpp"
#include "mannequin/skeleton/bvh.hpp"

namespace mannequin::mocap {

struct BvhSourceOptions {
  std::string file;
  double unit_scale_to_m = 0.01;  ///< metres per file unit
  /// (body name, BVH joint name) pairs to publish.
  std::vector<std::pair<std::string, std::string>> bodies;
  double rate = 1.0;     ///< playback rate factor (2 = twice as fast); > 0
  bool loop = false;     ///< restart at start_frame after end_frame (capture time keeps increasing)
  long long start_frame = 0;
  long long end_frame = -1;  ///< inclusive; negative counts from the end
  bool paced = true;     ///< false: frames as fast as next() is called (tests, benchmarks)
  bool mark_calibration = true;  ///< flag the first frame as the calibration pose
  /// Skip the T-pose frames a converter puts before the capture (skeleton::bvhIsTPose) from start_frame on,
  /// so that neither the playback nor the calibration (the first frame) sees them.
  bool skip_tpose = true;
};

class BvhSource final : public Source {
 public:
  /// \throws skeleton::BvhError for a bad file, std::invalid_argument for unknown joints or a bad range.
  explicit BvhSource(BvhSourceOptions options);
  std::optional<Frame> next(std::chrono::microseconds timeout) override;
  bool finished() const override { return finished_; }
  std::string kind() const override { return "bvh"; }
  std::string describe() const override;
  const skeleton::Bvh& bvh() const { return bvh_; }
  /// The frame of file frame `frame` played `loops` times before (no pacing, no side effect).
  Frame frameAt(int frame, std::uint64_t loops) const;
  /// File frames played: firstFrame()..lastFrame() (after the T-pose frames skipped).
  int firstFrame() const { return first_; }
  int lastFrame() const { return last_; }
  /// Leading T-pose frames skipped (options.skip_tpose).
  int skippedTPoseFrames() const { return skipped_tpose_; }

 private:
  BvhSourceOptions options_;
  skeleton::Bvh bvh_;
  std::vector<int> joints_;
  int first_ = 0, last_ = 0;
  int skipped_tpose_ = 0;
  int frame_ = 0;
  std::uint64_t loops_ = 0;
  bool finished_ = false;
  bool started_ = false;
  std::int64_t start_ns_ = 0;
  mutable std::vector<math::SE3> world_;
};

}  // namespace mannequin::mocap
