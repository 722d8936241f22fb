// The session loop shared by the live sim service and the offline run: see step_driver.hpp.
#include "mannequin/sim/step_driver.hpp"

#include <cmath>

namespace mannequin::sim {

StepDriver::Added StepDriver::addFrame(const mocap::Frame& frame, const std::string& source, double reanchor_threshold) {
  Added out;
  out.taken = world_->addMocap(frame, source);
  if (!world_->anchored(source)) {
    world_->anchor(frame.stamp_ns, source);
    out.anchored = true;
    return out;
  }
  out.drift_s = static_cast<double>(frame.stamp_ns - world_->captureTimeNs(source)) * 1e-9 - world_->config().interpolation_delay;
  if (std::abs(out.drift_s) > reanchor_threshold) {
    world_->anchor(frame.stamp_ns, source);
    out.reanchored = true;
  }
  return out;
}

bool StepDriver::due(std::int64_t capture_ns, const std::string& source) const {
  const std::int64_t step_ns = std::llround(world_->config().step * 1e9);
  return world_->captureTimeNs(source) + step_ns <= capture_ns;
}

long StepDriver::stepTo(std::int64_t capture_ns, const std::string& source) {
  long steps = 0;
  while (due(capture_ns, source)) {
    if (hooks_.proceed && !hooks_.proceed()) break;
    stepOnce();
    ++steps;
  }
  return steps;
}

bool StepDriver::stepOnce() {
  if (hooks_.before) hooks_.before();
  const bool ok = world_->step();
  if (hooks_.after) hooks_.after(ok);
  return ok;
}

}  // namespace mannequin::sim
