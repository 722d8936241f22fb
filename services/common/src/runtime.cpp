#include "mannequin/service/runtime.hpp"

#include <spdlog/spdlog.h>

#include <csignal>
#include <stdexcept>

namespace mannequin::service {

void addCommonOptions(CLI::App& app, CommonOptions& o, bool config_required) {
  auto* c = app.add_option("--config", o.config, "service config (YAML)")->check(CLI::ExistingFile);
  if (config_required) c->required();
  app.add_option("--name", o.name, "instance name (message source, heartbeat name)");
  app.add_option("--publish", o.publish, "endpoint to bind (tcp://HOST:PORT, ipc://PATH); repeatable, overrides the config");
  app.add_option("--connect", o.connect, "publisher endpoint to connect to; repeatable, overrides the config");
  app.add_option("--duration", o.duration, "stop after this many seconds (0: until SIGINT/SIGTERM)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn, error")->capture_default_str();
  app.add_option("--heartbeat-period", o.heartbeat_period, "seconds between heartbeats")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 60.0));
}

void setupLogging(const std::string& level) {
  const auto l = spdlog::level::from_str(level);
  if (l == spdlog::level::off && level != "off") throw std::invalid_argument("unknown log level '" + level + "'");
  spdlog::set_level(l);
  spdlog::set_pattern("%^%l%$ %v");
}

namespace {
std::atomic<bool>& stopFlag() {
  static std::atomic<bool> flag{false};
  return flag;
}
extern "C" void onStopSignal(int) { stopFlag().store(true); }
}  // namespace

const std::atomic<bool>& installStopSignals() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  return stopFlag();
}

}  // namespace mannequin::service
