#pragma once
/// \file step_driver.hpp
/// \brief Drives a World from a stream of mocap frames: the one session loop of the live sim service
/// and of the offline run (mannequin-simulate, mannequin-batch).
///
/// A frame is added to its mocap source, whose capture clock is anchored to the World clock at its
/// first frame (World::anchor); then the World is stepped while one more step keeps that source's
/// capture time at or before the frame's (replay semantics: the targets of every step are sampled
/// between frames already received). Hooks run before and after each step: timed triggers and the
/// collision lockstep before, totals, the scenario watch and publishing after.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "mannequin/mocap/frame.hpp"
#include "mannequin/sim/world.hpp"

namespace mannequin::sim {

class StepDriver {
 public:
  struct Hooks {
    /// Checked before each step of stepTo(): false ends it (a duration reached, a stop signal).
    std::function<bool()> proceed;
    /// Before each step (timed triggers, the collision query).
    std::function<void()> before;
    /// After each step, with World::step's result (totals, the scenario watch, publishing).
    std::function<void(bool ok)> after;
  };
  /// What addFrame did.
  struct Added {
    bool taken = false;       ///< World::addMocap took the frame (not a duplicate, an older one, an unused source)
    bool anchored = false;    ///< the source's clock was anchored at this frame, its first
    bool reanchored = false;  ///< the source's clock was anchored again at this frame (drift past the threshold)
    double drift_s = 0.0;     ///< capture time of the frame − the source's capture time now − interpolation delay (s)
  };

  explicit StepDriver(World& world) : world_(&world) {}
  void setHooks(Hooks hooks) { hooks_ = std::move(hooks); }

  /// Adds `frame` to mocap source `source` and anchors the source's clock at it when it is not anchored
  /// yet, or (live mode) when the clocks drifted apart by more than `reanchor_threshold` s.
  Added addFrame(const mocap::Frame& frame, const std::string& source,
                 double reanchor_threshold = std::numeric_limits<double>::infinity());
  /// Whether one more step keeps `source`'s capture time at or before `capture_ns`.
  bool due(std::int64_t capture_ns, const std::string& source) const;
  /// Steps (with the hooks) while due(capture_ns, source) and Hooks::proceed allows. Returns the steps taken.
  long stepTo(std::int64_t capture_ns, const std::string& source);
  /// One step with the hooks (the live mode's paced step). Returns World::step's result.
  bool stepOnce();

  World& world() { return *world_; }

 private:
  World* world_;
  Hooks hooks_;
};

/// An exact average rate out of a fixed step: tick() is true `rate` times per simulated second (sim.world
/// at world_rate, the offline run's samples), the fraction carried from one tick to the next.
class RateDivider {
 public:
  RateDivider(double rate, double step) : per_step_(rate * step) {}
  bool tick() {
    phase_ += per_step_;
    if (phase_ < 1.0 - 1e-9) return false;
    phase_ -= 1.0;
    return true;
  }

 private:
  double per_step_, phase_ = 0.0;
};

}  // namespace mannequin::sim
