#pragma once
/// \file kinetics_recorder.hpp
/// \brief A World's mannequins sampled over a run for their whole-body kinetics (libs/kinetics): each
/// sample keeps a mannequin's configuration and the contacts and loads on it (World::kineticsInputs);
/// at the end the motion is differentiated (kinetics::differentiate, its zero-lag filter) and every sample
/// solved (kinetics::KineticsSolver): the ground reaction the motion needs, how the contacts carry it,
/// the residual no contact explains. Used by the offline run (mannequin-simulate, mannequin-batch).
#include <string>
#include <vector>

#include "mannequin/kinetics/kinetics.hpp"
#include "mannequin/kinetics/motion.hpp"
#include "mannequin/sim/world.hpp"

namespace mannequin::sim {

/// One mannequin's kinetics over a run.
struct MannequinKinetics {
  std::string mannequin;
  kinetics::KineticsSummary summary;        ///< frames 0: nothing sampled (physics off, never calibrated)
  std::vector<double> time_s;               ///< per sample: the World's time
  std::vector<kinetics::KineticsFrame> frames;  ///< per sample (kept only when asked)
};

class KineticsRecorder {
 public:
  explicit KineticsRecorder(const World& world);
  /// Appends a sample of every mannequin that is calibrated (a mannequin's samples start at its
  /// calibration; call after every step). Nothing with physics off.
  void sample(const World& world);
  /// Solves the samples (taken every dt seconds): per mannequin, the motion differentiated over every
  /// sample, then every `every`-th sample solved (sampling each step keeps the sim's fast motion out of
  /// the filter's band — no aliasing — while a coarser solve keeps the cost low); its summary (weight
  /// from the model's mass and the physics' gravity) and, with keep_frames, each solved sample's frame.
  /// A mannequin with fewer than 3 samples gets an empty summary.
  std::vector<MannequinKinetics> solve(const World& world, double dt, int every = 1,
                                       const kinetics::DifferentiationOptions& options = {}, bool keep_frames = false) const;

 private:
  struct Track {
    std::vector<double> t;
    std::vector<math::VectorX> q;
    std::vector<std::vector<kinetics::ContactPoint>> contacts;
    std::vector<std::vector<kinetics::Load>> loads;
  };
  std::vector<Track> tracks_;
};

}  // namespace mannequin::sim
