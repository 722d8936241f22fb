#pragma once
/// \file offline.hpp
/// \brief The sim service's World run offline, in one process (no network): a sim config, a capture
/// (the config's `mocap` config, or a BVH / C3D file replacing its capture), stepped as fast as
/// possible in replay semantics (deterministic), the step diagnostics and the postures' ergonomic
/// scores accumulated, optionally the sim.world messages written to an MCAP file. Shared by
/// mannequin-simulate and mannequin-batch (tools/simulate, tools/batch).
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/mocap/source.hpp"
#include "mannequin/sim/kinetics_recorder.hpp"
#include "mannequin/sim/run_totals.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/simservice/config.hpp"

namespace mannequin::simservice {

/// The load a hand force stands for in RULA's force/load and REBA's load/force scores: |F| / g₀ (kg-force,
/// g₀ = 9.80665 m/s²), whatever its direction (the sheets score a load held and a force exerted alike).
inline double handLoadKg(const math::Vector3& force_n) { return force_n.norm() / 9.80665; }

/// Per mannequin, the postures' ergonomic scores over the run (RULA and REBA of the worse side, sampled
/// at the world rate once calibrated). libs/ergonomics' task input per side: the load in that hand from the
/// World (sim::World::handForces: what it holds and the contacts on it; handLoadKg) with physics on, none
/// without; not static, not repeated, good coupling — what a capture cannot say.
struct ErgonomicsSummary {
  std::string mannequin;
  /// Per hand [left, right], over the scored samples with physics on: |World::handForces| (N) summed and
  /// its largest, the largest load (kg, handLoadKg) given to the scores.
  std::array<double, 2> hand_force_sum_n{}, hand_force_max_n{}, hand_load_max_kg{};
  long long hand_force_samples = 0;
  double meanHandForce(int side) const {
    return hand_force_samples > 0 ? hand_force_sum_n[static_cast<std::size_t>(side)] / static_cast<double>(hand_force_samples)
                                  : std::numeric_limits<double>::quiet_NaN();
  }
  int rula_max = 0, reba_max = 0;
  std::array<double, 4> rula_time_s{};  ///< at RULA action level 1..4
  std::array<double, 5> reba_time_s{};  ///< at REBA action level 0..4
  long long samples = 0;
  long long failures = 0;  ///< postures the evaluator refused (non-finite q)
};

/// What a run measured (mannequin-simulate's --json keys): the steps' totals (sim::RunTotals) and the run's.
struct OfflineSummary : sim::RunTotals {
  long long frames = 0, lcp_failures = 0, worlds = 0;
  double sim_time_s = 0, wall_s = 0;
  // the balance controller (physics.balance_controller): solves and failed updates (all mannequins, at the end)
  bool balance_controller = false;
  long long balance_solves = 0, balance_failures = 0;
  bool physics = false;
  std::vector<ErgonomicsSummary> ergonomics;
  /// Per mannequin, the whole-body kinetics of the simulated motion sampled at the world rate (physics on;
  /// sim::KineticsRecorder): the ground reaction it needs, how the contacts carry it, the residual.
  std::vector<sim::MannequinKinetics> kinetics;
  /// The scenario (sim config `scenario`, --scenario): "" without one; the states entered with their sim
  /// time (the initial state at the first step the engine ran), the triggers sent, the actions the World
  /// does not apply yet (World::scenarioUnappliedActions).
  struct ScenarioEntry {
    double t = 0;
    std::string state;
    std::string events;  ///< the fired transitions' labels ("" for the initial state)
  };
  std::string scenario, scenario_state;
  std::vector<ScenarioEntry> scenario_timeline;
  long long scenario_triggers = 0, scenario_unapplied_actions = 0, scenario_states = 0;

  double realtimeFactor() const { return wall_s > 0 ? sim_time_s / wall_s : kNaN; }
};

/// The figures of a run that every summary carries (mannequin-simulate --json, mannequin-batch's
/// summary.json), as JSON members without the braces: "frames", "steps", "sim_time_s", "wall_s",
/// "realtime_factor", "nan_steps", "lcp_failures", "max_penetration_m", "max_contacts", "mean_contacts",
/// "foot_contact_fraction", "min_balance_distance_m", "min_force_margin_n", "grf_mean_over_weight"
/// (groundReactionOverWeight). Numbers with 17 significant digits (the same double prints the same text),
/// null when not finite.
std::string summaryJsonMembers(const OfflineSummary& s);

/// The mean vertical contact force on every mannequin over their total weight: Σ_m grf_mean_m / Σ_m weight_m
/// over the mannequins with kinetics samples (one mannequin: its kinetics' grf_mean_over_weight); NaN
/// without any. Over a motion that starts and ends at rest, momentum balance wants 1.
double groundReactionOverWeight(const OfflineSummary& s);

/// One mannequin's kinetics as a JSON object: "mannequin", "samples", "weight_n", "grf_mean_over_weight",
/// "residual_force_mean_n", "residual_force_peak_n", "residual_moment_peak_nm", "peak_external_force_n"
/// (docs/kinetics.md); the ratios null without samples.
std::string kineticsJson(const sim::MannequinKinetics& k);

/// A bad input file (config, mannequin, scene, capture, a non-finite sample): the message names the
/// FILE (and line or frame). Tools exit 2 on it.
class OfflineInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OfflineOptions {
  std::string config = "configs/sim/sim_demo.yaml";  ///< sim config (core::findData)
  /// A capture replacing the one of the sim config's `mocap` config: a .bvh (the mocap config's map and
  /// bodies kept), or a .c3d (source: c3d with `c3d_mapping`; the mannequins' control frames reduced
  /// to the mapping's bodies), or a .mcap recording (its mocap.frame messages, e.g. from mannequin-record,
  /// in log-time order: the bodies as recorded, one source). "" keeps the mocap config's.
  std::string mocap;
  std::string c3d_mapping = "configs/mappings/c3d_sample01.yaml";
  std::string mannequin;  ///< mannequin config for every mannequin ("" keeps the sim config's)
  std::string scene;      ///< scene file: turns the physics on with this scene ("" keeps the config's)
  std::string scenario;   ///< scenario file replacing the config's `scenario` ("" keeps the config's)
  double duration = -1;   ///< s of simulation (≤ 0: the whole capture)
  std::string out;        ///< MCAP file of the sim.world messages ("" none)
  bool progress = false;  ///< a progress bar with ETA on stderr
  std::string progress_label;
};

/// Called once per world sample (world_rate), after the summary's ergonomics of that sample: the World,
/// and per mannequin the sample's assessment (nullptr when not calibrated or refused).
using SampleHook = std::function<void(const sim::World&, const std::vector<const ergonomics::Assessment*>&)>;
/// Called after each step with the step's wall time (s).
using StepHook = std::function<void(const sim::World&, double step_wall_s)>;

class OfflineRun {
 public:
  /// Loads the config, capture, mannequins and scene.
  /// \throws OfflineInputError naming FILE:LINE (or FILE: frame) of what is bad.
  explicit OfflineRun(const OfflineOptions& options);
  ~OfflineRun();
  OfflineRun(const OfflineRun&) = delete;
  OfflineRun& operator=(const OfflineRun&) = delete;

  /// Steps the whole capture (or `duration`). \throws OfflineInputError for a non-finite capture sample
  /// (FILE: frame N: body B) — the MCAP file (if any) is then removed.
  OfflineSummary run(const SampleHook& on_sample = {}, const StepHook& on_step = {});

  const SimServiceConfig& config() const { return config_; }
  const sim::World& world() const { return *world_; }
  /// The capture's length in s (0 when the source cannot say).
  double captureLength() const { return capture_length_s_; }
  /// The capture file played.
  const std::string& captureFile() const { return capture_file_; }

 private:
  /// A capture and the mocap sources it drives (World source names); feeds_[0] is the clock the World steps to.
  struct Feed {
    std::unique_ptr<mocap::Source> source;
    std::vector<std::string> names;
    std::string file;
    double length_s = 0;
    std::optional<mocap::Frame> pending;  ///< read, not yet fed
  };
  OfflineOptions options_;
  SimServiceConfig config_;
  std::unique_ptr<mocap::Source> source_;  ///< the main capture (nullptr when every mocap source has its own)
  std::vector<Feed> feeds_;
  std::unique_ptr<sim::World> world_;
  std::vector<ergonomics::Evaluator> evaluators_;
  double capture_length_s_ = 0;
  std::string capture_file_;
};

}  // namespace mannequin::simservice
