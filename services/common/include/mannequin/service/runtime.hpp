#pragma once
/// \file runtime.hpp
/// \brief The service kit: the options every service accepts, its config with command-line overrides,
/// its endpoints, runService (core::runMain + logging level + stop signals) and the one service loop.
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <yaml-cpp/yaml.h>

#include "mannequin/core/config.hpp"
#include "mannequin/transport/health.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/transport/subscriber.hpp"

namespace mannequin::service {

/// Options every service accepts (the launcher passes --name, --publish, --connect).
struct CommonOptions {
  std::string config;                 ///< --config FILE (YAML)
  std::string name;                   ///< --name: Header.source and heartbeat name (default: the config's, else the service)
  std::vector<std::string> publish;   ///< --publish ENDPOINT (repeatable): overrides the config's `publish`
  std::vector<std::string> connect;   ///< --connect ENDPOINT (repeatable): overrides the config's `connect`
  double duration = 0.0;              ///< --duration S: stop by itself after S seconds (0 = run until a signal)
  std::string log_level = "info";     ///< --log-level
  double heartbeat_period = 0.5;      ///< --heartbeat-period S
  std::string security;               ///< --security FILE: its `security` section replaces the config's
  /// --io-threads N: ZeroMQ I/O threads of the service's context (ZMQ_IO_THREADS). 1 suits a single host;
  /// a publisher with many CURVE subscribers spreads their encryption over N threads (docs/cluster.md).
  int io_threads = 1;
};

/// Whether a service takes a config file: every service but the render node, whose view file
/// (--view) plays that part and whose network options all come from the command line.
enum class ConfigFile { kRequired, kNone };

/// Adds the common options to a CLI11 app (--config is required; absent with ConfigFile::kNone).
void addCommonOptions(CLI::App& app, CommonOptions& options, ConfigFile config = ConfigFile::kRequired);

/// A service's command line: the CLI11 app with the common options (add the service's own to `app`).
struct Cli {
  explicit Cli(std::string description, ConfigFile config = ConfigFile::kRequired);
  CLI::App app;
  CommonOptions options;
  /// core::runMain for a service: parses, sets the --log-level, installs the stop signals, then runs
  /// body(stop). Exit codes as core::runMain (0, 1 when the body throws, 2 on a bad command line).
  int run(int argc, char** argv, const std::function<int(const std::atomic<bool>& stop)>& body);
};

/// Loads --config (FILE:LINE on syntax errors) and applies the command-line overrides to the tree;
/// without --config (ConfigFile::kNone) an empty map. \throws core::ConfigError.
core::ConfigNode loadConfig(const CommonOptions& options, const std::function<void(YAML::Node&)>& overrides = {});

/// A service's CURVE keys, from its config's `security` section (docs/cluster.md, Security):
///   security:
///     secret_key_file: keys/sim.key_secret        # required; mode 0600
///     public_key_file: keys/sim.key               # optional; must be the secret's public key
///     server_public_key_file: keys/cluster.key    # the publishers' key, for every endpoint not in servers
///     servers:                                    # per publisher connected to: its key
///       - {connect: tcp://10.0.0.10:5601, public_key_file: keys/mocap.key}
///     authorized_keys: [keys/render1.key, "Z85..."]  # clients admitted by this service's publisher: a key
///                                                    # file where one exists, else a 40-character Z85 key
/// With `connect`, server_public_key_file or servers is required. Relative paths are relative to the
/// config file's directory. No section: plaintext, as before.
struct Security {
  std::optional<transport::CurveServerOptions> server;  ///< for the service's publisher
  std::optional<transport::CurveClientOptions> client;  ///< for the service's subscriber
  bool enabled() const { return server.has_value(); }
};
/// Reads `security` (absent: disabled). `connects`: the service has publishers to connect to.
/// \throws core::ConfigError "FILE:LINE: field 'security.x': ..." naming the config entry of a bad,
/// missing or world-readable key file or a bad key.
Security readSecurity(const core::ConfigNode& config, bool connects);
/// The `security` section of a file holding only that (--security FILE; mannequin-launch writes one per
/// service of a deployment with security). \throws core::ConfigError "FILE:LINE: ...".
Security readSecurityFile(const std::string& path, bool connects);

/// Who a service is on the network: the command line wins over the config (`name`, `publish`, `connect`);
/// its CURVE keys come from the `security` section of --security FILE if given, else of the config.
struct Endpoints {
  std::string name;
  std::vector<std::string> publish;
  std::vector<std::string> connect;
  Security security;
};
/// Whether a service must publish: every service but a render node outside a deployment (no --publish:
/// no publisher, no heartbeats).
enum class Publish { kRequired, kOptional };
/// \throws core::ConfigError when there is no endpoint to publish on (Publish::kRequired) or the
/// `security` section is bad.
Endpoints resolveEndpoints(const CommonOptions& options, const core::ConfigNode& config, const std::string& default_name,
                           Publish publish = Publish::kRequired);

/// The publisher of a service: its name, publish endpoints and CURVE server keys (if any).
transport::PublisherOptions publisherOptions(const Endpoints& endpoints);
/// The subscriber of a service: its name, connect endpoints and CURVE client keys (if any).
transport::SubscriberOptions subscriberOptions(const Endpoints& endpoints);

/// The loop of every service: health RUNNING and a heartbeat at start; then, until a stop signal,
/// `duration` seconds (0: no limit) or the iteration returning false, one iteration (which waits on its
/// own sockets or source, up to its poll period) and a heartbeat when its period is due; at the end
/// STOPPING and a last heartbeat. The duration counts from construction until run() starts, then from run().
class ServiceLoop {
 public:
  ServiceLoop(transport::HealthReporter& health, const std::atomic<bool>& stop, double duration_s = 0.0);
  /// `health` null: a process without heartbeats (a render node without --publish); the loop is the same.
  ServiceLoop(transport::HealthReporter* health, const std::atomic<bool>& stop, double duration_s = 0.0);
  /// `on_heartbeat` runs after every heartbeat published (per-period statistics restart), `on_stop`
  /// once before the STOPPING heartbeat (final statistics). Returns core::kExitOk.
  int run(const std::function<bool()>& iteration, const std::function<void()>& on_heartbeat = {},
          const std::function<void()>& on_stop = {});
  /// True once a stop signal came or the duration is over (for waits inside an iteration).
  bool stopping() const;
  double elapsed() const;  ///< s since run() started

 private:
  transport::HealthReporter* health_;
  const std::atomic<bool>& stop_;
  double duration_s_;
  std::int64_t start_ns_ = 0;
};

}  // namespace mannequin::service
