#include "mannequin/deploy/deployment.hpp"

#include <unistd.h>

#include <limits>
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

const std::string& Deployment::endpointOf(const std::string& name) const {
  for (const auto& s : services)
    if (s.name == name) return s.publish;
  throw std::out_of_range("deployment '" + this->name + "': no service '" + name + "'");
}

std::vector<std::string> Deployment::commandLine(std::size_t i) const {
  const ServiceSpec& s = services.at(i);
  std::vector<std::string> argv{s.exec, "--name", s.name, "--publish", s.publish};
  for (const auto& c : s.connect) {
    argv.push_back("--connect");
    argv.push_back(endpointOf(c));
  }
  argv.insert(argv.end(), s.args.begin(), s.args.end());
  return argv;
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
  root.allowOnly({"name", "run_dir", "heartbeat_timeout", "stop_timeout", "restart", "services"});
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
  std::set<std::string> names;
  const ConfigNode services = root["services"];
  for (const ConfigNode& s : services.items()) {
    s.allowOnly({"name", "exec", "args", "publish", "connect", "restart"});
    ServiceSpec spec;
    spec.line = s.line();
    spec.name = s["name"].str();
    if (spec.name.empty() || spec.name.find_first_of(" /") != std::string::npos) s["name"].fail("not a usable service name");
    if (!names.insert(spec.name).second) s["name"].fail("duplicate service name '" + spec.name + "'");
    spec.exec = s["exec"].str();
    if (auto a = s.find("args"))
      for (const std::string& x : a->strings()) spec.args.push_back(expandRunDir(x, d.run_dir));
    const ConfigNode pub = s["publish"];
    spec.publish = expandRunDir(pub.str(), d.run_dir);
    try {
      if (transport::normalizeEndpoint(spec.publish).back() == '*')
        throw std::invalid_argument("an ephemeral port cannot be used in a deployment (the others must know it)");
    } catch (const std::exception& e) {
      pub.fail(e.what());
    }
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
