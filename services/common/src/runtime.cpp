#include "mannequin/service/runtime.hpp"

#include "mannequin/core/clock.hpp"
#include "mannequin/core/main.hpp"

#include <filesystem>

namespace mannequin::service {

void addCommonOptions(CLI::App& app, CommonOptions& o, ConfigFile config) {
  if (config == ConfigFile::kRequired)
    app.add_option("--config", o.config, "service config (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--name", o.name, "instance name (message source, heartbeat name)");
  app.add_option("--publish", o.publish, "endpoint to bind (tcp://HOST:PORT, ipc://PATH); repeatable, overrides the config");
  app.add_option("--connect", o.connect, "publisher endpoint to connect to; repeatable, overrides the config");
  app.add_option("--duration", o.duration, "stop after this many seconds (0: until SIGINT/SIGTERM)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  app.add_option("--security", o.security,
                 "YAML file whose 'security' section (CURVE keys) replaces the config's; mannequin-launch writes one per "
                 "service of a deployment with security")
      ->check(CLI::ExistingFile);
  app.add_option("--heartbeat-period", o.heartbeat_period, "seconds between heartbeats")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 60.0));
  app.add_option("--io-threads", o.io_threads,
                 "ZeroMQ I/O threads (ZMQ_IO_THREADS); more than 1 spreads the CURVE encryption for many subscribers over "
                 "cores (a sim host with cores to spare); 1 on a small single host")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
}

Cli::Cli(std::string description, ConfigFile config) : app(std::move(description)) {
  addCommonOptions(app, options, config);
}

int Cli::run(int argc, char** argv, const std::function<int(const std::atomic<bool>& stop)>& body) {
  return core::runMain(app, argc, argv, [&] {
    core::setupLogging(options.log_level);
    return body(core::installStopSignals());
  });
}

core::ConfigNode loadConfig(const CommonOptions& o, const std::function<void(YAML::Node&)>& overrides) {
  if (o.config.empty()) {  // ConfigFile::kNone: the command line only
    YAML::Node empty(YAML::NodeType::Map);
    if (overrides) overrides(empty);
    return core::ConfigNode(empty, "(command line)");
  }
  core::ConfigNode loaded = core::ConfigNode::load(o.config);  // syntax errors with their line
  if (!overrides) return loaded;
  YAML::Node raw = YAML::Clone(YAML::LoadFile(o.config));
  overrides(raw);
  return core::ConfigNode(raw, o.config);
}

Endpoints resolveEndpoints(const CommonOptions& o, const core::ConfigNode& config, const std::string& default_name,
                           Publish publish) {
  Endpoints e;
  e.name = o.name.empty() ? config.get("name", default_name) : o.name;
  e.publish = o.publish;
  if (e.publish.empty() && config.has("publish")) e.publish = config["publish"].strings();
  if (e.publish.empty() && publish == Publish::kRequired) throw core::ConfigError(o.config + ": no publish endpoint (config 'publish' or --publish)");
  e.connect = o.connect;
  if (e.connect.empty() && config.has("connect")) e.connect = config["connect"].strings();
  if (o.security.empty()) {
    e.security = readSecurity(config, !e.connect.empty());
  } else {
    e.security = readSecurityFile(o.security, !e.connect.empty());
  }
  return e;
}

namespace {
// a path of the config, relative to the config file's directory
std::string besideConfig(const core::ConfigNode& node) {
  const std::string path = node.str();
  if (path.empty()) node.fail("empty path");
  const std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  return (std::filesystem::path(node.file()).parent_path() / p).lexically_normal().string();
}

std::string keyFrom(const core::ConfigNode& node, bool secret) {
  const std::string path = besideConfig(node);
  try {
    return transport::readKeyFile(path, secret);
  } catch (const std::exception& e) {
    node.fail(e.what());
  }
}
}  // namespace

Security readSecurity(const core::ConfigNode& config, bool connects) {
  Security s;
  const auto section = config.find("security");
  if (!section) return s;
  if (!section->isMap())
    section->fail("expected a map (secret_key_file, public_key_file, server_public_key_file, servers, authorized_keys)");
  section->allowOnly({"secret_key_file", "public_key_file", "server_public_key_file", "servers", "authorized_keys"});
  if (!transport::hasCurve()) section->fail("this libzmq has no CURVE support");
  const core::ConfigNode secret_node = (*section)["secret_key_file"];
  const std::string secret = keyFrom(secret_node, true);
  const std::string public_key = transport::curvePublicKey(secret);
  if (const auto p = section->find("public_key_file"))
    if (keyFrom(*p, false) != public_key) p->fail("not the public key of " + besideConfig(secret_node));

  transport::CurveServerOptions server;
  server.secret_key = secret;
  const core::ConfigNode listed = (*section)["authorized_keys"];
  const std::vector<core::ConfigNode> entries = listed.isSequence() ? listed.items() : std::vector<core::ConfigNode>{listed};
  for (const core::ConfigNode& entry : entries) {
    // a key file if one exists there (a path can be 40 characters of the Z85 alphabet too, e.g.
    // /tmp/mq-e2e-hosts-4169/keys/launch.a.key), else a Z85 key written inline, else a missing key file
    const std::string text = entry.str();
    std::error_code ec;
    const bool is_file = !text.empty() && std::filesystem::is_regular_file(besideConfig(entry), ec);
    server.authorized_keys.push_back(!is_file && transport::isZ85Key(text) ? text : keyFrom(entry, false));
  }
  s.server = std::move(server);

  transport::CurveClientOptions client{public_key, secret, {}};
  if (const auto sp = section->find("server_public_key_file")) client.server_public_key = keyFrom(*sp, false);
  if (const auto servers = section->find("servers")) {
    for (const core::ConfigNode& server : servers->items()) {
      server.allowOnly({"connect", "public_key_file"});
      const std::string endpoint = server["connect"].str();
      if (!client.server_keys.emplace(endpoint, keyFrom(server["public_key_file"], false)).second)
        server["connect"].fail("'" + endpoint + "' listed twice");
    }
  }
  if (!client.server_public_key.empty() || !client.server_keys.empty())
    s.client = std::move(client);
  else if (connects)
    section->fail("missing key 'server_public_key_file' or 'servers' (the service connects to publishers)");
  return s;
}

Security readSecurityFile(const std::string& path, bool connects) {
  const core::ConfigNode file = core::ConfigNode::load(path);
  file.allowOnly({"security"});
  if (!file.has("security")) file.fail("no 'security' section");
  return readSecurity(file, connects);
}

transport::PublisherOptions publisherOptions(const Endpoints& e) {
  transport::PublisherOptions o;
  o.source = e.name;
  o.endpoints = e.publish;
  o.curve = e.security.server;
  return o;
}

transport::SubscriberOptions subscriberOptions(const Endpoints& e) {
  transport::SubscriberOptions o;
  o.name = e.name;
  o.endpoints = e.connect;
  o.curve = e.security.client;
  return o;
}

ServiceLoop::ServiceLoop(transport::HealthReporter& health, const std::atomic<bool>& stop, double duration_s)
    : ServiceLoop(&health, stop, duration_s) {}

ServiceLoop::ServiceLoop(transport::HealthReporter* health, const std::atomic<bool>& stop, double duration_s)
    : health_(health), stop_(stop), duration_s_(duration_s), start_ns_(core::steadyNs()) {}

bool ServiceLoop::stopping() const { return stop_.load() || (duration_s_ > 0 && elapsed() >= duration_s_); }

double ServiceLoop::elapsed() const { return static_cast<double>(core::steadyNs() - start_ns_) * 1e-9; }

int ServiceLoop::run(const std::function<bool()>& iteration, const std::function<void()>& on_heartbeat,
                     const std::function<void()>& on_stop) {
  start_ns_ = core::steadyNs();
  if (health_ != nullptr) {
    health_->setState(v1::SERVICE_STATE_RUNNING);
    health_->tick(true);
  }
  while (!stopping()) {
    if (!iteration()) break;
    if (health_ != nullptr && health_->tick() && on_heartbeat) on_heartbeat();
  }
  if (on_stop) on_stop();
  if (health_ != nullptr) {
    health_->setState(v1::SERVICE_STATE_STOPPING);
    health_->tick(true);
  }
  return core::kExitOk;
}

}  // namespace mannequin::service
