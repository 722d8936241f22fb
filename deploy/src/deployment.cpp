#include "mannequin/deploy/deployment.hpp"

#include <unistd.h>

#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include "mannequin/core/config.hpp"
#include "mannequin/transport/publisher.hpp"

namespace mannequin::deploy {

using core::ConfigNode;

std::string expandRunDir(const std::string& text, const std::string& run_dir) {
  std::string out = text;
  const std::string key = "${RUN_DIR}";
  for (std::size_t pos = out.find(key); pos != std::string::npos; pos = out.find(key, pos + run_dir.size()))
    out.replace(pos, key.size(), run_dir);
  return out;
}

std::string tcpHost(const std::string& endpoint) {
  if (endpoint.rfind("tcp://", 0) != 0) return {};
  const std::string rest = endpoint.substr(6);
  return rest.substr(0, rest.rfind(':'));
}

bool isLoopbackHost(const std::string& host) {
  return host.rfind("127.", 0) == 0 || host == "[::1]" || host == "::1" || host == "localhost" || host == "lo";
}

namespace {
std::string tcpPort(const std::string& endpoint) {
  const std::size_t colon = endpoint.rfind(':');
  return colon == std::string::npos ? std::string() : endpoint.substr(colon + 1);
}
bool isWildcardHost(const std::string& host) { return host == "*" || host == "0.0.0.0" || host == "[::]" || host == "::"; }
}  // namespace

const Host* Deployment::findHost(const std::string& host) const {
  for (const auto& h : hosts)
    if (h.name == host) return &h;
  return nullptr;
}

std::string Deployment::hostNames() const {
  std::string out;
  for (const auto& h : hosts) out += (out.empty() ? "" : ", ") + h.name;
  return out;
}

const std::string& Deployment::endpointOf(const std::string& name) const {
  for (const auto& s : services)
    if (s.name == name) return s.publish;
  throw std::out_of_range("deployment '" + this->name + "': no service '" + name + "'");
}

const std::string& Deployment::addressOf(const std::string& name) const {
  for (const auto& s : services)
    if (s.name == name) return s.address;
  throw std::out_of_range("deployment '" + this->name + "': no service '" + name + "'");
}

bool Deployment::runsOn(std::size_t i, const std::string& host) const {
  return !multiHost() || services.at(i).host == host;
}

std::vector<std::string> Deployment::commandLine(std::size_t i, bool resume) const {
  const ServiceSpec& s = services.at(i);
  std::vector<std::string> argv{s.exec, "--name", s.name, "--publish", s.publish};
  for (const auto& c : s.connect) {
    argv.push_back("--connect");
    argv.push_back(addressOf(c));
  }
  if (security) {
    argv.push_back("--security");
    argv.push_back(securityFile(i));
  }
  if (!s.checkpoint.empty()) {
    argv.push_back("--checkpoint");
    argv.push_back(s.checkpoint);
    if (resume) {
      argv.push_back("--resume");
      argv.push_back(s.checkpoint);
    }
  }
  argv.insert(argv.end(), s.args.begin(), s.args.end());
  return argv;
}

std::string Deployment::publicKeyFile(const std::string& key_name) const {
  return (std::filesystem::path(security.value().key_dir) / (key_name + ".key")).string();
}

std::string Deployment::secretKeyFile(const std::string& key_name) const {
  return (std::filesystem::path(security.value().key_dir) / (key_name + ".key_secret")).string();
}

std::string Deployment::launcherKeyName(const std::string& host) { return host.empty() ? "launch" : "launch." + host; }

std::string Deployment::securityFile(std::size_t i) const {
  return (std::filesystem::path(run_dir) / "security" / (services.at(i).name + ".yaml")).string();
}

namespace {
// a YAML double-quoted scalar
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// every key name a publisher admits: the services, every launcher, the clients
std::vector<std::string> admittedKeyNames(const Deployment& d) {
  std::vector<std::string> names;
  for (const auto& s : d.services) names.push_back(s.name);
  if (d.multiHost())
    for (const auto& h : d.hosts) names.push_back(Deployment::launcherKeyName(h.name));
  else
    names.push_back(Deployment::launcherKeyName(""));
  for (const auto& c : d.security.value().clients) names.push_back(c);
  return names;
}
}  // namespace

std::string Deployment::securityFileText(std::size_t i) const {
  const ServiceSpec& s = services.at(i);
  std::string out = "# written by mannequin-launch from " + source + " for service '" + s.name + "'" +
                    (s.host.empty() ? std::string() : " (host " + s.host + ")") + "\nsecurity:\n";
  out += "  secret_key_file: " + quoted(secretKeyFile(s.name)) + "\n";
  out += "  public_key_file: " + quoted(publicKeyFile(s.name)) + "\n";
  if (!s.connect.empty()) {
    out += "  servers:\n";
    for (const std::string& c : s.connect)
      out += "    - {connect: " + quoted(addressOf(c)) + ", public_key_file: " + quoted(publicKeyFile(c)) + "}\n";
  }
  out += "  authorized_keys:\n";
  for (const std::string& k : admittedKeyNames(*this)) out += "    - " + quoted(publicKeyFile(k)) + "\n";
  return out;
}

transport::CurveClientOptions Deployment::clientKeys(const std::string& secret_key_file) const {
  transport::CurveClientOptions c;
  c.secret_key = transport::readKeyFile(secret_key_file, true);
  c.public_key = transport::curvePublicKey(c.secret_key);
  for (const auto& s : services) c.server_keys[s.address] = transport::readKeyFile(publicKeyFile(s.name), false);
  return c;
}

void checkKeys(const Deployment& d, const std::string& host) {
  if (!d.security) return;
  const std::string& where = d.security->where;
  auto fail = [&](const std::string& file, const std::string& message, const std::string& whose) {
    const bool missing = !std::filesystem::exists(file);
    core::failAt(where, "security.key_dir",
                 message + " (" + whose +
                     (missing ? "; generate it with: mannequin-keys generate " + std::filesystem::path(file).stem().string() +
                                    " --dir " + d.security->key_dir
                              : std::string()) +
                     ")");
  };
  auto read = [&](const std::string& key_name, bool secret, const std::string& whose) {
    const std::string file = secret ? d.secretKeyFile(key_name) : d.publicKeyFile(key_name);
    try {
      return transport::readKeyFile(file, secret);
    } catch (const std::exception& e) {
      fail(file, e.what(), whose);
    }
    return std::string();  // not reached: fail throws
  };
  auto whoseKey = [&](const std::string& key_name) -> std::string {
    for (const auto& s : d.services)
      if (s.name == key_name) return "the key of service '" + s.name + "'" + (s.host.empty() ? "" : " on host " + s.host);
    for (const auto& c : d.security->clients)
      if (c == key_name) return "the key of client '" + c + "'";
    return "the key of the launcher" + (key_name.size() > 7 ? " of host " + key_name.substr(7) : std::string());
  };
  std::map<std::string, std::string> publics;  // key name → public key
  for (const std::string& k : admittedKeyNames(d)) publics[k] = read(k, false, "the public " + whoseKey(k).substr(4));
  // the secrets of this host (every host's when none is given)
  std::vector<std::string> secrets;
  for (std::size_t i = 0; i < d.services.size(); ++i)
    if (host.empty() || d.runsOn(i, host)) secrets.push_back(d.services[i].name);
  if (!d.multiHost())
    secrets.push_back(Deployment::launcherKeyName(""));
  else
    for (const auto& h : d.hosts)
      if (host.empty() || h.name == host) secrets.push_back(Deployment::launcherKeyName(h.name));
  for (const std::string& k : secrets) {
    const std::string secret = read(k, true, "the secret " + whoseKey(k).substr(4));
    if (transport::curvePublicKey(secret) != publics[k])
      fail(d.secretKeyFile(k), d.secretKeyFile(k) + ": not the secret key of " + d.publicKeyFile(k), whoseKey(k));
  }
}

namespace {
RestartOptions parseRestart(const ConfigNode& n, RestartOptions r) {
  n.allowOnly({"policy", "max_restarts", "backoff_initial", "backoff_max", "stable_after"});
  if (auto p = n.find("policy")) {
    static const RestartPolicy kPolicies[] = {RestartPolicy::kNever, RestartPolicy::kOnFailure, RestartPolicy::kAlways};
    r.policy = kPolicies[p->choice({"never", "on-failure", "always"})];
  }
  if (auto m = n.find("max_restarts")) r.max_restarts = static_cast<int>(m->integerIn(0, std::numeric_limits<int>::max()));
  r.backoff_initial = n.getIn("backoff_initial", r.backoff_initial, 0.0, 3600.0);
  r.backoff_max = n.getIn("backoff_max", r.backoff_max, 0.0, 3600.0);
  r.stable_after = n.getIn("stable_after", r.stable_after, 0.0, 1e6);
  return r;
}

Deployment readDeployment(const ConfigNode& root, const std::string& run_dir) {
  root.allowOnly({"name", "run_dir", "heartbeat_timeout", "stop_timeout", "restart", "hosts", "security", "services"});
  Deployment d;
  d.source = root.file();
  d.name = root["name"].str();
  d.run_dir = run_dir;
  if (d.run_dir.empty()) d.run_dir = root.get("run_dir", std::string());
  if (d.run_dir.empty()) d.run_dir = "/tmp/mannequin-" + d.name + "-" + std::to_string(getuid());
  d.heartbeat_timeout = root.getIn("heartbeat_timeout", 3.0, 0.05, 3600.0);
  d.stop_timeout = root.getIn("stop_timeout", 3.0, 0.05, 600.0);
  RestartOptions defaults;
  if (auto r = root.find("restart")) defaults = parseRestart(*r, defaults);
  if (const auto hosts = root.find("hosts")) {
    for (const ConfigNode& h : hosts->items()) {
      h.allowOnly({"name", "address"});
      Host host;
      host.line = h.line();
      host.name = h["name"].str();
      if (host.name.empty() || host.name.find_first_of(" /@") != std::string::npos) h["name"].fail("not a usable host name");
      if (d.findHost(host.name)) h["name"].fail("duplicate host name '" + host.name + "'");
      host.address = h["address"].str();
      if (host.address.empty() || host.address.find_first_of(" /") != std::string::npos || host.address.find("://") != std::string::npos)
        h["address"].fail("expected an IP address or a DNS name, got '" + host.address + "'");
      d.hosts.push_back(host);
    }
    if (d.hosts.empty()) hosts->fail("no hosts (a single-host deployment has no 'hosts' key)");
  }
  if (const auto sec = root.find("security")) {
    sec->allowOnly({"key_dir", "clients"});
    DeploymentSecurity security;
    const ConfigNode dir = (*sec)["key_dir"];
    std::filesystem::path key_dir(dir.str());
    if (key_dir.empty()) dir.fail("empty path");
    if (key_dir.is_relative()) key_dir = std::filesystem::path(root.file()).parent_path() / key_dir;
    security.key_dir = std::filesystem::absolute(key_dir).lexically_normal().string();
    security.where = dir.where();
    if (auto c = sec->find("clients")) {
      for (const ConfigNode& client : c->items()) {
        const std::string name = client.str();
        if (name.empty() || name.find_first_of(" /") != std::string::npos) client.fail("not a usable key name");
        security.clients.push_back(name);
      }
    }
    if (!transport::hasCurve()) sec->fail("this libzmq has no CURVE support");
    d.security = security;
  } else if (d.multiHost()) {
    root["hosts"].fail("a multi-host deployment needs 'security' (CURVE: key_dir, clients; docs/cluster.md)");
  }
  std::set<std::string> names;
  std::map<std::string, std::string> bound;  // "host|tcp port" or "host|endpoint" → service
  const ConfigNode services = root["services"];
  for (const ConfigNode& s : services.items()) {
    s.allowOnly({"name", "host", "exec", "args", "publish", "connect", "restart", "checkpoint"});
    ServiceSpec spec;
    spec.line = s.line();
    spec.name = s["name"].str();
    if (spec.name.empty() || spec.name.find_first_of(" /") != std::string::npos) s["name"].fail("not a usable service name");
    if (!names.insert(spec.name).second) s["name"].fail("duplicate service name '" + spec.name + "'");
    const Host* host = nullptr;
    if (auto h = s.find("host")) {
      if (!d.multiHost()) h->fail("this deployment has no 'hosts' (a single-host deployment runs every service here)");
      spec.host = h->str();
      host = d.findHost(spec.host);
      if (host == nullptr) h->fail("unknown host '" + spec.host + "' (hosts: " + d.hostNames() + ")");
    } else if (d.multiHost()) {
      s.fail("service '" + spec.name + "' is on no host: a multi-host deployment needs 'host' (one of " + d.hostNames() + ")");
    }
    spec.exec = s["exec"].str();
    if (auto a = s.find("args"))
      for (const std::string& x : a->strings()) spec.args.push_back(expandRunDir(x, d.run_dir));
    if (auto c = s.find("checkpoint")) {
      spec.checkpoint = expandRunDir(c->str(), d.run_dir);
      if (spec.checkpoint.empty() || spec.checkpoint.back() == '/') c->fail("not a file path");
    }
    const ConfigNode pub = s["publish"];
    spec.publish = expandRunDir(pub.str(), d.run_dir);
    try {
      if (transport::normalizeEndpoint(spec.publish).back() == '*')
        throw std::invalid_argument("an ephemeral port cannot be used in a deployment (the others must know it)");
    } catch (const std::exception& e) {
      pub.fail(e.what());
    }
    const std::string bind_host = tcpHost(spec.publish);
    spec.address = spec.publish;
    if (host == nullptr) {
      if (!bind_host.empty() && !isLoopbackHost(bind_host))
        pub.fail("'" + spec.publish + "' is reachable from other machines: a deployment without 'hosts' binds ipc or loopback "
                 "tcp only (127.0.0.1, [::1], localhost); across machines declare hosts and security (docs/cluster.md)");
    } else {
      if (bind_host.empty())
        pub.fail("a service of a multi-host deployment publishes on tcp (tcp://*:PORT): the other hosts' launchers follow "
                 "its heartbeats, got '" + spec.publish + "'");
      if (isLoopbackHost(bind_host))
        pub.fail("'" + spec.publish + "' is loopback only: the other hosts cannot reach it (bind tcp://*:PORT)");
      if (isWildcardHost(bind_host)) {
        const bool v6 = host->address.find(':') != std::string::npos;
        spec.address = "tcp://" + (v6 ? "[" + host->address + "]" : host->address) + ":" + tcpPort(spec.publish);
      }
    }
    const std::string key = spec.host + "|" + (bind_host.empty() ? spec.publish : "tcp port " + tcpPort(spec.publish));
    if (const auto [it, fresh] = bound.emplace(key, spec.name); !fresh)
      pub.fail("'" + spec.publish + "' is already bound by service '" + it->second + "'" +
               (spec.host.empty() ? std::string() : " on host '" + spec.host + "'"));
    if (auto c = s.find("connect")) spec.connect = c->strings();
    spec.restart = defaults;
    if (auto r = s.find("restart")) spec.restart = parseRestart(*r, defaults);
    d.services.push_back(spec);
  }
  if (d.services.empty()) services.fail("no services");
  // connect targets must exist
  const auto items = services.items();
  for (std::size_t i = 0; i < d.services.size(); ++i)
    for (const std::string& c : d.services[i].connect)
      if (!names.count(c)) items[i]["connect"].fail("no service named '" + c + "' in this deployment");
  return d;
}
}  // namespace

Deployment parseDeployment(const std::string& yaml, const std::string& source, const std::string& run_dir) {
  return readDeployment(ConfigNode::parse(yaml, source), run_dir);
}

Deployment loadDeployment(const std::string& path, const std::string& run_dir) {
  return readDeployment(ConfigNode::load(path), run_dir);
}

}  // namespace mannequin::deploy
