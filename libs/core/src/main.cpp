#include "mannequin/core/main.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include <csignal>
#include <exception>
#include <stdexcept>

namespace mannequin::core {

namespace {
// CLI11 prints help (code 0) or the error with a hint on stderr; its own codes (> 100) become kExitUsage.
int usage(CLI::App& app, const CLI::ParseError& e) { return app.exit(e) == 0 ? kExitOk : kExitUsage; }

int runBody(CLI::App& app, const std::function<int()>& body) {
  try {
    setupLogging("info");
    return body();
  } catch (const CLI::ParseError& e) {  // a check of the options' combination, done in the body
    return usage(app, e);
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
  } catch (...) {
    spdlog::critical("unknown exception");
  }
  return kExitFailure;
}
}  // namespace

int runMain(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return usage(app, e);
  }
  return runBody(app, body);
}

int runMain(CLI::App& app, std::vector<std::string> args, const std::function<int()>& body) {
  std::reverse(args.begin(), args.end());  // CLI11 takes the vector in reverse order
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return usage(app, e);
  }
  return runBody(app, body);
}

void setupLogging(const std::string& level) {
  const auto l = spdlog::level::from_str(level);
  if (l == spdlog::level::off && level != "off") throw std::invalid_argument("unknown log level '" + level + "'");
  static const bool on_stderr = [] {  // logs on stderr, results (JSON, CSV, tables) on stdout
    spdlog::set_default_logger(spdlog::stderr_color_mt("mannequin"));
    return true;
  }();
  (void)on_stderr;
  spdlog::set_level(l);
  spdlog::set_pattern("%^%l%$ %v");
}

CLI::Validator logLevelCheck() {
  return CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"});
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

}  // namespace mannequin::core
