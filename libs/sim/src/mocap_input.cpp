// Mocap input of a World: its sources, the anchoring of their capture clocks, the glitch filter of
// incoming frames (MocapGlitches) and the stream-gap watch.
#include "world_state.hpp"

namespace mannequin::sim {

World::Source* World::findSource(const std::string& name) {
  for (auto& src : sources_)
    if (src->name == name) return src.get();
  return nullptr;
}
const World::Source* World::findSource(const std::string& name) const {
  for (const auto& src : sources_)
    if (src->name == name) return src.get();
  return nullptr;
}
std::vector<std::string> World::mocapSources() const {
  std::vector<std::string> out;
  for (const auto& src : sources_) out.push_back(src->name);
  return out;
}
const mocap::Frame* World::latestMocap(const std::string& source) const {
  const Source* src = findSource(source);
  return src != nullptr ? src->buffer.newest() : nullptr;
}
bool World::anchored(const std::string& source) const {
  const Source* src = findSource(source);
  return src != nullptr && src->anchored;
}

void World::anchor(std::int64_t capture_ns, const std::string& source) {
  Source* src = findSource(source);
  if (src == nullptr) return;
  if (src->anchored) src->back = true;  // re-anchored: the targets jump in capture time, they catch up instead
  src->anchored = true;
  src->anchor_capture_ns = capture_ns;
  src->anchor_step = steps_;
}

std::int64_t World::captureTimeNs(const std::string& source) const {
  const Source* src = findSource(source);
  if (src == nullptr) return 0;
  const double dt_ns = config_.step * 1e9;
  return src->anchor_capture_ns +
         static_cast<std::int64_t>(std::llround(static_cast<double>(steps_ - src->anchor_step) * dt_ns)) -
         static_cast<std::int64_t>(std::llround(config_.interpolation_delay * 1e9));
}


bool World::addMocap(const mocap::Frame& in, const std::string& source) {
  Source* src = findSource(source);
  if (src == nullptr) return false;
  const mocap::Frame* newest = src->buffer.newest();
  const bool restart = newest != nullptr && newest->stamp_ns - in.stamp_ns > src->buffer.window_ns();
  if (newest != nullptr && !restart && in.stamp_ns <= newest->stamp_ns) {
    ++(in.stamp_ns == newest->stamp_ns ? glitches_.duplicate_frames : glitches_.out_of_order_frames);
    return false;
  }
  // a tracked body with a non-finite pose (a glitch of the tracker) is taken as untracked
  const mocap::Frame* frame = &in;
  mocap::Frame clean;
  for (const mocap::Body& b : in.bodies)
    if (b.tracked && !(b.pose.p.allFinite() && b.pose.R.allFinite())) {
      if (frame == &in) clean = in;
      frame = &clean;
    }
  if (frame == &clean)
    for (mocap::Body& b : clean.bodies)
      if (b.tracked && !(b.pose.p.allFinite() && b.pose.R.allFinite())) {
        b.tracked = false;
        ++glitches_.non_finite_bodies;
      }
  // a tracked body farther from its last tracked pose than max_target_speed allows since then (a marker
  // swap): untracked in this frame, so its target holds; a body that really moved is taken again once the
  // time since its last tracked pose allows the distance. When every tracked body jumps together it is the
  // actor (or the capture: a looping file) relocated, not a swap: taken as it is.
  if (newest != nullptr && !restart) {
    std::size_t checked = 0;
    jumps_.clear();
    for (std::size_t k = 0; k < frame->bodies.size(); ++k) {
      const mocap::Body& b = frame->bodies[k];
      if (!b.tracked) continue;
      const BodySample last = src->buffer.sample(b.name, newest->stamp_ns + 1);
      if (!last.ever_tracked) continue;
      ++checked;
      const double allowed = config_.max_target_speed * static_cast<double>(frame->stamp_ns - last.last_tracked_ns) * 1e-9 + kJumpTolerance;
      if ((b.pose.p - last.pose.p).norm() > allowed) jumps_.push_back(k);
    }
    if (!jumps_.empty() && jumps_.size() < checked) {
      if (frame == &in) clean = in;
      frame = &clean;
      for (std::size_t k : jumps_) clean.bodies[k].tracked = false;
      glitches_.pose_jumps += jumps_.size();
    }
  }
  if (restart) {
    ++glitches_.capture_restarts;
    src->buffer.restart(*frame);
    if (src->anchored) anchor(frame->stamp_ns, source);  // its clock: the service's anchoring, at the frame
  } else {
    src->buffer.add(*frame);
  }
  if (src->gap) src->back = true;  // the stream is back after a gap: its frames are taken in again
  src->gap = false;
  for (auto& m : mannequins_)
    if (!m->calibrated && sources_[static_cast<std::size_t>(m->source)].get() == src) calibrate(*m, *frame);
  return true;
}

void World::detectStreamGaps() {
  for (auto& src : sources_)
    if (const mocap::Frame* f = src->buffer.newest(); f != nullptr && src->anchored && !src->gap &&
                                                       captureTimeNs(src->name) - f->stamp_ns > std::llround(config_.occlusion_hold * 1e9)) {
      src->gap = true;
      ++glitches_.stream_gaps;
    }
}

}  // namespace mannequin::sim
