#include "mannequin/sim/kinetics_recorder.hpp"

#include <algorithm>

namespace mannequin::sim {

KineticsRecorder::KineticsRecorder(const World& world) : tracks_(static_cast<std::size_t>(world.numMannequins())) {}

void KineticsRecorder::sample(const World& world) {
  if (!world.physics()) return;
  for (int m = 0; m < world.numMannequins() && static_cast<std::size_t>(m) < tracks_.size(); ++m) {
    if (!world.calibrated(m)) continue;
    Track& tr = tracks_[static_cast<std::size_t>(m)];
    tr.t.push_back(world.time());
    tr.q.push_back(world.q(m));
    tr.contacts.emplace_back();
    tr.loads.emplace_back();
    world.kineticsInputs(m, tr.contacts.back(), tr.loads.back());
  }
}

std::vector<MannequinKinetics> KineticsRecorder::solve(const World& world, double dt, int every,
                                                       const kinetics::DifferentiationOptions& options,
                                                       bool keep_frames) const {
  const std::size_t stride = static_cast<std::size_t>(std::max(1, every));
  std::vector<MannequinKinetics> out;
  const math::Vector3 g = world.config().physics.gravity;
  for (std::size_t m = 0; m < tracks_.size(); ++m) {
    const Track& tr = tracks_[m];
    const skeleton::Model& model = world.model(static_cast<int>(m));
    MannequinKinetics mk;
    mk.mannequin = world.name(static_cast<int>(m));
    mk.summary.weight_n = model.totalMass() * g.norm();
    if (tr.q.size() >= 3) {
      const kinetics::MotionDerivatives md = kinetics::differentiate(model, tr.q, dt, options);
      kinetics::KineticsOptions ko;
      ko.gravity = g;
      kinetics::KineticsSolver solver(model, ko);
      std::vector<kinetics::KineticsFrame> frames;
      frames.reserve(tr.q.size());
      std::vector<double> times;
      for (std::size_t k = 0; k < tr.q.size(); k += stride) {
        frames.push_back(solver.solve(tr.q[k], md.v[k], md.a[k], tr.contacts[k], tr.loads[k]));
        times.push_back(tr.t[k]);
      }
      mk.summary = kinetics::summarize(frames, mk.summary.weight_n);
      if (keep_frames) {
        mk.time_s = std::move(times);
        mk.frames = std::move(frames);
      }
    }
    out.push_back(std::move(mk));
  }
  return out;
}

}  // namespace mannequin::sim
