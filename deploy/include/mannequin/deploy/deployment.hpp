#pragma once
/// \file deployment.hpp
/// \brief A deployment file (configs/deployments/*.yaml): which services run, with which arguments,
/// where each publishes (its bound endpoint) and whom it connects to, restart policy.
///
/// Every service is started as
///   EXEC --name NAME --publish ENDPOINT [--connect ADDRESS_OF_X ...] ARGS...
/// with ${RUN_DIR} in endpoints and arguments replaced by the run directory (ipc sockets live there).
///
/// Single host (no `hosts:`): every service on this host; its publish endpoint is bound and connected to
/// as written, and must be ipc or loopback tcp (127.0.0.1, [::1], localhost: nothing reachable from
/// another machine).
/// Multi-host (`hosts: [{name, address}]`, each service a `host:`): the same file on every machine;
/// a service binds its `publish` endpoint on its host (tcp://*:PORT or tcp://0.0.0.0:PORT: every
/// interface; tcp://IP:PORT: that one) and the others connect to its `address`: tcp://HOST_ADDRESS:PORT
/// for a wildcard bind, the endpoint as written otherwise. A multi-host deployment needs `security`.
///
/// Security (`security: {key_dir, clients}`, CURVE, docs/cluster.md): every service NAME has the key pair
/// KEY_DIR/NAME.key and KEY_DIR/NAME.key_secret, the launcher of host H KEY_DIR/launch.H.key{,_secret}
/// (single host: launch.key{,_secret}); every publisher admits the public keys of every service, every
/// host's launcher and the `clients` (KEY_DIR/CLIENT.key), nobody else. Each service is given its keys
/// by `--security RUN_DIR/security/NAME.yaml`, a file the launcher writes (securityFileText).
#include <optional>
#include <string>
#include <vector>

#include "mannequin/transport/security.hpp"

namespace mannequin::deploy {

enum class RestartPolicy { kNever, kOnFailure, kAlways };

struct RestartOptions {
  RestartPolicy policy = RestartPolicy::kOnFailure;  ///< on-failure: restart unless it exited with 0
  int max_restarts = 5;          ///< more restarts than this → failed permanently
  double backoff_initial = 0.5;  ///< s before the first restart, doubled after each
  double backoff_max = 8.0;      ///< s
  double stable_after = 10.0;    ///< s of running that resets the backoff and the restart count
};

/// A machine of a multi-host deployment.
struct Host {
  std::string name;
  std::string address;  ///< IP address or DNS name the other hosts reach it at
  int line = 0;
};

/// The deployment's `security` section.
struct DeploymentSecurity {
  std::string key_dir;               ///< absolute (a relative one is taken from the deployment file's directory)
  std::vector<std::string> clients;  ///< further key names every publisher admits (KEY_DIR/NAME.key)
  std::string where;                 ///< "FILE:LINE" of key_dir (errors about key files point there)
};

struct ServiceSpec {
  std::string name;
  std::string host;                  ///< multi-host: the host it runs on ("" in a single-host deployment)
  std::string exec;                  ///< executable: a path, or a name looked up next to mannequin-launch, then in PATH
  std::vector<std::string> args;     ///< extra arguments (after the generated ones)
  std::string publish;               ///< endpoint it binds on its host (expanded)
  std::string address;               ///< endpoint the others (and the launchers' monitors) connect to
  std::vector<std::string> connect;  ///< names of the services it subscribes to
  /// Key `checkpoint` (expanded; "" none): a file the service keeps its state in (mannequin-sim
  /// --checkpoint); a restart resumes from it (--resume). Removed when the launcher starts and stops.
  std::string checkpoint;
  RestartOptions restart;
  int line = 0;                      ///< line of its entry in the file
};

struct Deployment {
  std::string name;
  std::string source;          ///< file path
  std::string run_dir;         ///< expanded
  double heartbeat_timeout = 3.0;  ///< s without a heartbeat before a service is shown late
  double stop_timeout = 3.0;       ///< s between SIGTERM and SIGKILL at shutdown
  std::vector<Host> hosts;         ///< empty: a single-host deployment
  std::optional<DeploymentSecurity> security;  ///< unset: plaintext (single host only)
  std::vector<ServiceSpec> services;  ///< start order (stopped in reverse)

  bool multiHost() const { return !hosts.empty(); }
  /// The host named `name`, nullptr if none.
  const Host* findHost(const std::string& name) const;
  /// "a, b, c": the hosts' names (for messages).
  std::string hostNames() const;
  /// The endpoint service `name` binds (on its host). \throws std::out_of_range.
  const std::string& endpointOf(const std::string& name) const;
  /// The endpoint the others connect to for service `name`. \throws std::out_of_range.
  const std::string& addressOf(const std::string& name) const;
  /// Whether service i runs on `host` ("" = this single host: every service of a single-host file).
  bool runsOn(std::size_t i, const std::string& host) const;
  /// argv of service i (argv[0] = exec as written); with security, `--security securityFile(i)` after
  /// the --connect arguments; with a checkpoint, `--checkpoint FILE`, and with `resume` `--resume FILE`.
  std::vector<std::string> commandLine(std::size_t i, bool resume = false) const;

  /// Security: KEY_DIR/NAME.key and KEY_DIR/NAME.key_secret.
  std::string publicKeyFile(const std::string& key_name) const;
  std::string secretKeyFile(const std::string& key_name) const;
  /// The key name of the launcher of `host` ("launch.HOST", single host "launch").
  static std::string launcherKeyName(const std::string& host);
  /// RUN_DIR/security/NAME.yaml: the --security file of service i.
  std::string securityFile(std::size_t i) const;
  /// Its text: the `security` section of service i (its key pair, the public key of each service it
  /// connects to by its address, the authorized keys), absolute paths. Requires `security`.
  std::string securityFileText(std::size_t i) const;
  /// The CURVE client keys of a subscriber to every service (a launcher's monitor, a recorder): the key
  /// pair of `secret_key_file`, each service's public key by its address. \throws std::runtime_error
  /// naming a bad key file. Requires `security`.
  transport::CurveClientOptions clientKeys(const std::string& secret_key_file) const;
};

/// Reads a deployment file. `run_dir` ("" = the file's `run_dir`, else /tmp/mannequin-<name>-<uid>)
/// replaces ${RUN_DIR}. \throws core::ConfigError "FILE:LINE: field '...': ..." (unknown keys,
/// duplicate names, a connect naming no service, a service without publish endpoint, bad numbers;
/// single host: a publish endpoint reachable from other machines; multi-host: a service on no host or
/// an unknown one, a duplicate host, an endpoint the other hosts cannot reach (ipc, loopback), two
/// services binding one port of a host).
Deployment loadDeployment(const std::string& path, const std::string& run_dir = {});
Deployment parseDeployment(const std::string& yaml, const std::string& source, const std::string& run_dir = {});

/// Checks the key files before anything starts: the public key of every service, every host's launcher
/// and every client; the secret keys (readable by the owner only, matching the public key) of the
/// services of `host` and its launcher — of every host when `host` is "" (the machine the keys were
/// generated on). Nothing without `security`. \throws core::ConfigError "FILE:LINE: field
/// 'security.key_dir': KEYFILE: ..." naming whose key it is.
void checkKeys(const Deployment& d, const std::string& host);

/// Replaces every ${RUN_DIR} of `text`.
std::string expandRunDir(const std::string& text, const std::string& run_dir);

/// The host part of a tcp endpoint ("tcp://HOST:PORT" → "HOST", brackets of an IPv6 address kept),
/// "" for another transport.
std::string tcpHost(const std::string& endpoint);
/// Whether a tcp host is loopback only: 127.x.y.z, [::1], localhost, the interface lo.
bool isLoopbackHost(const std::string& host);

}  // namespace mannequin::deploy
