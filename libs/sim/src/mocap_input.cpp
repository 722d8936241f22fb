// Mocap input of a World: its sources, the anchoring of their capture clocks, the glitch filter of
// incoming frames (MocapGlitches) and the stream-gap watch.
#include "world_state.hpp"

namespace mannequin::sim {

std::vector<std::string> World::mocapSources() const { return model_.sources; }
const mocap::Frame* World::latestMocap(const std::string& source) const {
  const int k = findSource(source);
  return k >= 0 ? data_->sources[static_cast<std::size_t>(k)].buffer.newest() : nullptr;
}
bool World::anchored(const std::string& source) const {
  const int k = findSource(source);
  return k >= 0 && data_->sources[static_cast<std::size_t>(k)].anchored;
}

void World::anchor(std::int64_t capture_ns, const std::string& source) {
  const int k = findSource(source);
  if (k < 0) return;
  SourceData* src = &data_->sources[static_cast<std::size_t>(k)];
  if (src->anchored) src->back = true;  // re-anchored: the targets jump in capture time, they catch up instead
  src->anchored = true;
  src->anchor_capture_ns = capture_ns;
  src->anchor_step = data_->steps;
}

std::int64_t World::captureTimeNs(const std::string& source) const {
  const int k = findSource(source);
  return k < 0 ? 0 : sourceCaptureTimeNs(static_cast<std::size_t>(k));
}

std::int64_t World::sourceCaptureTimeNs(std::size_t source) const {
  const SourceData* src = &data_->sources[source];
  const double dt_ns = model_.config.step * 1e9;
  return src->anchor_capture_ns +
         static_cast<std::int64_t>(std::llround(static_cast<double>(data_->steps - src->anchor_step) * dt_ns)) -
         static_cast<std::int64_t>(std::llround(model_.config.interpolation_delay * 1e9));
}


bool World::addMocap(const mocap::Frame& in, const std::string& source) {
  const int k_src = findSource(source);
  if (k_src < 0) return false;
  SourceData* src = &data_->sources[static_cast<std::size_t>(k_src)];
  const mocap::Frame* newest = src->buffer.newest();
  const bool restart = newest != nullptr && newest->stamp_ns - in.stamp_ns > src->buffer.window_ns();
  if (newest != nullptr && !restart && in.stamp_ns <= newest->stamp_ns) {
    ++(in.stamp_ns == newest->stamp_ns ? data_->glitches.duplicate_frames : data_->glitches.out_of_order_frames);
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
        ++data_->glitches.non_finite_bodies;
      }
  // a tracked body farther from its last tracked pose than max_target_speed allows since then (a marker
  // swap): untracked in this frame, so its target holds; a body that really moved is taken again once the
  // time since its last tracked pose allows the distance. When every tracked body jumps together it is the
  // actor (or the capture: a looping file) relocated, not a swap: taken as it is.
  if (newest != nullptr && !restart) {
    std::size_t checked = 0;
    data_->jumps.clear();
    for (std::size_t k = 0; k < frame->bodies.size(); ++k) {
      const mocap::Body& b = frame->bodies[k];
      if (!b.tracked) continue;
      const BodySample last = src->buffer.sample(b.name, newest->stamp_ns + 1);
      if (!last.ever_tracked) continue;
      ++checked;
      const double allowed = model_.config.max_target_speed * static_cast<double>(frame->stamp_ns - last.last_tracked_ns) * 1e-9 + kJumpTolerance;
      if ((b.pose.p - last.pose.p).norm() > allowed) data_->jumps.push_back(k);
    }
    if (!data_->jumps.empty() && data_->jumps.size() < checked) {
      if (frame == &in) clean = in;
      frame = &clean;
      for (std::size_t k : data_->jumps) clean.bodies[k].tracked = false;
      data_->glitches.pose_jumps += data_->jumps.size();
    }
  }
  if (restart) {
    ++data_->glitches.capture_restarts;
    src->buffer.restart(*frame);
    if (src->anchored) anchor(frame->stamp_ns, source);  // its clock: the service's anchoring, at the frame
  } else {
    src->buffer.add(*frame);
  }
  if (src->gap) src->back = true;  // the stream is back after a gap: its frames are taken in again
  src->gap = false;
  for (std::size_t m = 0; m < model_.mannequins.size(); ++m)
    if (!data_->mannequins[m].calibrated && model_.mannequins[m].source == k_src) calibrate(m, *frame);
  return true;
}

void World::detectStreamGaps() {
  for (std::size_t k = 0; k < data_->sources.size(); ++k) {
    SourceData& src = data_->sources[k];
    if (const mocap::Frame* f = src.buffer.newest(); f != nullptr && src.anchored && !src.gap &&
                                                      sourceCaptureTimeNs(k) - f->stamp_ns > std::llround(model_.config.occlusion_hold * 1e9)) {
      src.gap = true;
      ++data_->glitches.stream_gaps;
    }
  }
}

}  // namespace mannequin::sim
