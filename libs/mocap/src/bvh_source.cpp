#include "mannequin/mocap/bvh_source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <stdexcept>

#include "mannequin/core/clock.hpp"

namespace mannequin::mocap {

namespace {
// BVH world (y up, actor facing +z) → room (z up, facing +x)
math::Matrix3 bvhToRoom() {
  math::Matrix3 A;
  A << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  return A;
}
}  // namespace

BvhSource::BvhSource(BvhSourceOptions options) : options_(std::move(options)) {
  if (!(options_.rate > 0) || !std::isfinite(options_.rate)) throw std::invalid_argument("bvh: rate must be > 0");
  skeleton::BvhReadOptions ro;
  ro.unit_scale_to_m = options_.unit_scale_to_m;
  bvh_ = skeleton::readBvhFile(options_.file, ro);
  if (bvh_.num_frames == 0) throw std::invalid_argument(options_.file + ": the capture has no frames");
  for (const auto& [name, joint] : options_.bodies) {
    const int j = skeleton::findBvhJoint(bvh_, joint);
    if (j < 0) throw std::invalid_argument(fmt::format("{}: no joint '{}' (body '{}')", options_.file, joint, name));
    joints_.push_back(j);
  }
  try {
    first_ = skeleton::resolveBvhFrame(bvh_, options_.start_frame);
    last_ = skeleton::resolveBvhFrame(bvh_, options_.end_frame);
  } catch (const std::out_of_range&) {
    throw std::invalid_argument(fmt::format("{}: frame range {}..{} outside the {} frames", options_.file,
                                            options_.start_frame, options_.end_frame, bvh_.num_frames));
  }
  if (last_ < first_)
    throw std::invalid_argument(fmt::format("{}: end frame {} before start frame {}", options_.file, last_, first_));
  if (options_.skip_tpose) {
    const int n = skeleton::bvhLeadingTPoseFrames(bvh_, first_);
    if (first_ + n > last_)
      throw std::invalid_argument(fmt::format("{}: every frame of {}..{} is a T-pose (arms spread, upright): nothing to play "
                                              "(skip_tpose: false plays them)", options_.file, first_, last_));
    if (n > 0) {
      spdlog::info("{}: {} a T-pose (arms spread horizontally, upright): skipped, playback and calibration start at frame {}",
                   options_.file, n > 1 ? fmt::format("frames {}..{} are", first_, first_ + n - 1) : fmt::format("frame {} is", first_),
                   first_ + n);
      first_ += n;
      skipped_tpose_ = n;
    }
  }
  frame_ = first_;
  world_.resize(bvh_.joints.size());
}

std::string BvhSource::describe() const {
  return fmt::format("BVH {} ({} frames at {:.1f} Hz, playing {}..{}{} at rate {}{}, {} bodies)", options_.file,
                     bvh_.num_frames, 1.0 / bvh_.frame_time, first_, last_,
                     skipped_tpose_ > 0 ? fmt::format(" after {} T-pose frame{}", skipped_tpose_, skipped_tpose_ > 1 ? "s" : "") : "",
                     options_.rate, options_.loop ? ", looped" : "", joints_.size());
}

Frame BvhSource::frameAt(int frame, std::uint64_t loops) const {
  const math::Matrix3 A = bvhToRoom();
  skeleton::bvhForwardKinematics(bvh_, skeleton::bvhFrame(bvh_, frame), world_, bvh_.unit_scale_to_m);
  Frame s;
  const std::uint64_t span = static_cast<std::uint64_t>(last_ - first_ + 1);
  const std::uint64_t index = loops * span + static_cast<std::uint64_t>(frame - first_);
  s.frame_number = index;
  s.stamp_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(index) * bvh_.frame_time * 1e9));
  s.calibration_pose = options_.mark_calibration && index == 0;
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    Body b;
    b.name = options_.bodies[k].first;
    b.id = joints_[k];
    b.pose.R = A * world_[joints_[k]].R;
    b.pose.p = A * world_[joints_[k]].p;
    s.bodies.push_back(b);
  }
  return s;
}

std::optional<Frame> BvhSource::next(std::chrono::microseconds timeout) {
  if (finished_) return std::nullopt;
  const std::uint64_t span = static_cast<std::uint64_t>(last_ - first_ + 1);
  const std::uint64_t index = loops_ * span + static_cast<std::uint64_t>(frame_ - first_);
  if (options_.paced) {
    if (!started_) {
      started_ = true;
      start_ns_ = core::steadyNs();
    }
    const auto due = start_ns_ + static_cast<std::int64_t>(static_cast<double>(index) * bvh_.frame_time / options_.rate * 1e9);
    if (!sleepUntil(due, timeout)) return std::nullopt;
  }
  Frame s = frameAt(frame_, loops_);
  if (++frame_ > last_) {
    if (options_.loop) {
      frame_ = first_;
      ++loops_;
    } else {
      finished_ = true;
    }
  }
  return s;
}

}  // namespace mannequin::mocap
