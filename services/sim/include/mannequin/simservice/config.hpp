#pragma once
/// \file config.hpp
/// \brief The sim service's YAML config (configs/sim/sim_*.yaml; reference in docs/cluster.md).
#include <string>
#include <vector>

#include "mannequin/core/config.hpp"
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
};

/// What steps the mannequins: the control library's Controller (default) or the KinematicTracker.
enum class StepperKind { kController, kKinematic };

struct SimServiceConfig {
  std::string name = "sim";
  std::vector<std::string> publish, connect;
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

}  // namespace mannequin::simservice
