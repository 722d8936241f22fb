#pragma once
/// \file config.hpp
/// \brief The sim service's YAML config (configs/sim/sim_*.yaml; reference in docs/cluster.md).
#include <optional>
#include <string>
#include <vector>

#include "mannequin/transport/security.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/scenario/scenario.hpp"
#include "mannequin/sim/world.hpp"

namespace mannequin::simservice {

enum class Mode { kLive, kReplay };
enum class CollisionMode { kNone, kService };

struct CollisionSettings {
  CollisionMode mode = CollisionMode::kNone;
  int period_steps = 10;     ///< a query every this many steps
  double deadline = 0.005;   ///< s to wait for the contacts of a query (live mode); past it: stale
  double replay_deadline = 2.0;  ///< s (replay mode waits this long before flagging stale)
  double margin = 0.02;      ///< m
};

struct MannequinEntry {
  std::string name;
  std::string config;        ///< configs/mannequins/*.yaml
  std::string root_frame = "pelvis";
  std::vector<sim::ControlFrameSpec> frames;
  std::string controller = "configs/control/mocap.yaml";  ///< stepper: controller
  /// Key `mocap_source`: the name of a `mocap_sources` entry whose frames drive this mannequin; "" (absent):
  /// the default source (frames of any publisher not listed in `mocap_sources`).
  std::string mocap_source;
  std::string where;         ///< "FILE:LINE" of its entry in the sim config ("" if not read from a file)
  std::string field;         ///< its path there ("mannequins[0]"), for errors found by buildMannequins
};

/// Key `mocap_sources` entry: a mocap service whose frames form their own source (one actor, one
/// capture system: its own buffer and clock anchor in the World). A frame belongs to the entry whose
/// `name` equals its Header.source (the publishing service's name, `--name`).
struct MocapSourceEntry {
  std::string name;                  ///< the mocap service's name (Header.source of its frames)
  std::vector<std::string> connect;  ///< its publisher endpoints (added to the subscriber's; may be empty)
  /// Key `mocap`: the mocap config mannequin-simulate plays offline for this source alone (resolved like the
  /// top-level `mocap`); "" when absent: the top-level capture drives it. The service ignores it.
  std::string mocap;
  std::string where;  ///< FILE:LINE of the entry
};

/// An operator trigger at a sim time (key `scenario.triggers`): what a scripted run (mannequin-simulate,
/// replay) gives the scenario where an operator would press a button.
struct TimedTrigger {
  double at = 0;  ///< s of sim time
  std::string name, value;
};

/// Key `scenario`: a scenario file (configs/scenarios/*.yaml) run by the World's loop (World::setScenario),
/// its state published on scenario.state, operator triggers read from scenario.trigger and `triggers`.
struct ScenarioSettings {
  std::string file;                    ///< "" : no scenario
  scenario::Scenario scenario;         ///< loaded and validated at parse
  std::vector<TimedTrigger> triggers;  ///< sorted by time
  double state_rate = 10.0;            ///< scenario.state per second of sim time (and at every switch)
  std::string where;                   ///< "FILE:LINE" of the key in the sim config
};

/// What steps the mannequins: the control library's Controller (default) or the KinematicTracker.
enum class StepperKind { kController, kKinematic };

struct SimServiceConfig {
  std::string name = "sim";
  std::vector<std::string> publish, connect;
  /// CURVE keys of its publisher and subscriber (service::Endpoints::security; unset: plaintext)
  std::optional<transport::CurveServerOptions> curve_server;
  std::optional<transport::CurveClientOptions> curve_client;
  Mode mode = Mode::kLive;
  double world_rate = 60.0;   ///< sim.world per second of simulation time (≤ 1/step)
  bool publish_on_mocap = false;  ///< also publish sim.world at the first step after each new mocap frame
  double reanchor_threshold = 0.5;  ///< s: live capture clock drifted this far → re-anchor
  sim::SimConfig world;
  StepperKind stepper = StepperKind::kController;
  std::vector<MannequinEntry> mannequins;
  std::vector<MocapSourceEntry> mocap_sources;  ///< key `mocap_sources` (empty: one default source)
  double status_period = 5.0;  ///< s of wall time between status lines (contacts, penetration, balance); 0: none
  CollisionSettings collision;
  /// Key `mocap`: the mocap config (configs/sim/mocap_*.yaml, its `source` section) mannequin-simulate
  /// reads the capture from when run offline; found with core::findData, else beside the sim config.
  /// The service ignores it (it gets mocap.frame). "" when absent.
  std::string mocap;
  ScenarioSettings scenario;  ///< key `scenario` (file "" when absent)
  /// Command line only (simservice/checkpoint.hpp): the checkpoint file kept ("" none), written at most
  /// every checkpoint_period s (at a sim.world publication), and the one to resume from at start ("" none).
  std::string checkpoint;
  double checkpoint_period = 0.1;
  std::string resume;
};

/// Key `physics` (sim::PhysicsConfig, docs/cluster.md): {enabled, gravity, scene (a scene file, collision::loadScene),
/// segment_margin, segment_material, self_collision, query_period_steps, activation_distance, calibration_clearance,
/// friction_edges, recovery_speed, max_rows}.
/// \throws core::ConfigError "FILE:LINE: field '...': ...".
SimServiceConfig parseSimConfig(const core::ConfigNode& root);
SimServiceConfig loadSimConfig(const std::string& path);

/// A path a config names: found with core::findData, else relative to the config file's directory.
/// \throws core::ConfigError at the node when neither exists.
std::string resolvePath(const core::ConfigNode& node);

/// Builds the World's mannequins (loads every mannequin config).
/// \throws core::ConfigError "FILE:LINE: field 'mannequins[i]': mannequin 'a': ..." naming the entry, then
/// the failure (a mannequin or controller config's own FILE:LINE error, a control frame the model lacks).
std::vector<sim::MannequinSetup> buildMannequins(const SimServiceConfig& config);

/// Sets the config's scenario (if any) on the World. \throws core::ConfigError at the sim config's
/// `scenario` key naming what the World lacks (a mannequin, control frame, object or value).
void setupScenario(sim::World& world, const SimServiceConfig& config);

/// Replaces the config's scenario with a file's (mannequin-simulate --scenario): its timed triggers are
/// kept when they are the new scenario's, else refused. \throws core::ConfigError.
void replaceScenario(SimServiceConfig& config, const std::string& file);

/// Feeds a run's timed triggers to the World as sim time passes (before each step).
class TriggerSchedule {
 public:
  explicit TriggerSchedule(const std::vector<TimedTrigger>& triggers) : triggers_(&triggers) {}
  /// Sends every trigger due at the World's time (at <= time + step/2); returns how many.
  int due(sim::World& world);
  /// Skips the triggers timed before `time` (a World resumed from a checkpoint); returns how many.
  std::size_t skipBefore(double time);
  std::size_t sent() const { return next_; }

 private:
  const std::vector<TimedTrigger>* triggers_;
  std::size_t next_ = 0;
};

}  // namespace mannequin::simservice
