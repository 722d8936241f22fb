// libFuzzer target for the BVH reader: any input either throws BvhError or yields a consistent Bvh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "mannequin/skeleton/bvh.hpp"

namespace sk = mannequin::skeleton;

namespace {

// aborts (a libFuzzer crash) when an invariant of an accepted file is broken
void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sk::Bvh bvh;
  try {
    bvh = sk::parseBvh(text, "fuzz.bvh");
  } catch (const sk::BvhError& e) {
    // every error names a line inside the input
    check(e.line() >= 1 && e.file() == "fuzz.bvh");
    return 0;
  }
  // the hierarchy: a root first, parents before children, channel slots contiguous
  check(!bvh.joints.empty() && bvh.joints[0].parent == -1 && !bvh.joints[0].end_site);
  int channels = 0;
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    const sk::BvhJoint& joint = bvh.joints[j];
    check(j == 0 || (joint.parent >= 0 && static_cast<std::size_t>(joint.parent) < j));
    check(joint.first_channel == channels && joint.channels.size() <= 6);
    check(joint.offset.allFinite());
    channels += static_cast<int>(joint.channels.size());
  }
  check(channels == bvh.num_channels);
  // the motion: exactly frames × channels finite values, a positive frame time
  check(bvh.num_frames >= 0 && bvh.frame_time > 0.0 && std::isfinite(bvh.frame_time));
  check(bvh.num_channels == 0 ||
        bvh.motion.size() == static_cast<std::size_t>(bvh.num_frames) * static_cast<std::size_t>(bvh.num_channels));
  for (const double v : bvh.motion) check(std::isfinite(v));
  // forward kinematics of the first and last frames gives rotations
  if (bvh.num_frames > 0) {
    for (const long long f : {0LL, -1LL}) {
      const std::vector<mannequin::math::SE3> world = sk::bvhWorldPoses(bvh, f);
      check(world.size() == bvh.joints.size());
      for (const auto& H : world) check(!H.R.allFinite() || mannequin::math::isRotation(H.R, 1e-6));
    }
  }
  return 0;
}
