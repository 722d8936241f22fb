#include "mannequin/sim/mocap_buffer.hpp"

#include <algorithm>

namespace mannequin::sim {

namespace {
const mocap::Body* findBody(const mocap::Frame& f, const std::string& name) {
  for (const mocap::Body& b : f.bodies)
    if (b.name == name) return &b;
  return nullptr;
}
}  // namespace

bool MocapBuffer::add(const mocap::Frame& frame) {
  if (!frames_.empty() && frame.stamp_ns <= frames_.back().stamp_ns) return false;
  frames_.push_back(frame);
  while (frames_.size() > 2 && frames_.back().stamp_ns - frames_.front().stamp_ns > window_ns_) frames_.pop_front();
  for (const mocap::Body& b : frame.bodies) {
    if (!b.tracked) continue;
    bool found = false;
    for (LastTracked& l : last_tracked_)
      if (l.name == b.name) {
        l.pose = b.pose;
        l.stamp_ns = frame.stamp_ns;
        found = true;
      }
    if (!found) last_tracked_.push_back({b.name, b.pose, frame.stamp_ns});
  }
  return true;
}

void MocapBuffer::restart(const mocap::Frame& frame) {
  frames_.clear();
  for (LastTracked& l : last_tracked_) l.stamp_ns = frame.stamp_ns;
  add(frame);
}

BodySample MocapBuffer::sample(const std::string& body, std::int64_t t_ns) const {
  BodySample out;
  for (const LastTracked& l : last_tracked_)
    if (l.name == body) {
      out.pose = l.pose;
      out.last_tracked_ns = l.stamp_ns;
      out.ever_tracked = true;
    }
  if (frames_.empty()) return out;
  // first frame after t (frames are in stamp order: add() refuses older ones)
  const std::size_t k = static_cast<std::size_t>(
      std::upper_bound(frames_.begin(), frames_.end(), t_ns, [](std::int64_t t, const mocap::Frame& f) { return t < f.stamp_ns; }) -
      frames_.begin());
  if (k == frames_.size() || k == 0) {  // past the newest (or before the oldest): that frame
    const mocap::Frame& f = k == 0 ? frames_.front() : frames_.back();
    const mocap::Body* b = findBody(f, body);
    if (b != nullptr && b->tracked) {
      out.pose = b->pose;
      out.tracked = true;
    }
    return out;
  }
  const mocap::Frame& f0 = frames_[k - 1];
  const mocap::Frame& f1 = frames_[k];
  const mocap::Body* b0 = findBody(f0, body);
  // a source sends its bodies in the same order frame after frame: try b0's place in f1 first
  const std::size_t i0 = b0 != nullptr ? static_cast<std::size_t>(b0 - f0.bodies.data()) : 0;
  const mocap::Body* b1 =
      b0 != nullptr && i0 < f1.bodies.size() && f1.bodies[i0].name == body ? &f1.bodies[i0] : findBody(f1, body);
  const bool t0 = b0 != nullptr && b0->tracked, t1 = b1 != nullptr && b1->tracked;
  if (t0 && t1) {
    const double gamma = static_cast<double>(t_ns - f0.stamp_ns) / static_cast<double>(f1.stamp_ns - f0.stamp_ns);
    out.pose = math::interpolate(b0->pose, b1->pose, gamma);
    out.tracked = true;
  } else if (t0) {
    out.pose = b0->pose;
    out.tracked = true;
  }
  // t0 untracked: occluded at t (the newer frame is not known to the past)
  return out;
}

}  // namespace mannequin::sim
