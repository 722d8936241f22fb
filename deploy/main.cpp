// mannequin-launch: runs every service of a deployment file on this host (see docs/cluster.md).
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "mannequin/core/main.hpp"
#include "mannequin/deploy/supervisor.hpp"
#include "mannequin/core/config.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-launch: starts every service of a deployment file on this host, prefixes their\n"
               "output, shows a status line from their heartbeats (services up, rates, lateness), restarts\n"
               "a crashed service with backoff, and stops all cleanly on Ctrl-C / SIGTERM / --duration."};
  std::string file, run_dir, summary_json;
  double duration = 0, status_period = 5.0;
  bool check = false, no_tty = false;
  app.add_option("deployment", file, "deployment file (YAML), e.g. configs/deployments/single-host.yaml")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--duration", duration, "stop everything after this many seconds (0: until Ctrl-C/SIGTERM)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--run-dir", run_dir, "directory of the ipc sockets (${RUN_DIR}); default from the file");
  app.add_option("--status-period", status_period, "seconds between status lines when not on a terminal (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-tty", no_tty, "print status lines instead of one live line even on a terminal");
  app.add_option("--summary-json", summary_json, "also write the final summary as JSON to this file");
  app.add_flag("--check", check, "read the deployment, print the command lines, start nothing");
  return core::runMain(app, argc, argv, [&] {
    const deploy::Deployment d = deploy::loadDeployment(file, run_dir);
    deploy::SupervisorOptions o;
    o.exec_dir = std::filesystem::canonical("/proc/self/exe").parent_path().string();
    o.tty = !no_tty && isatty(STDOUT_FILENO);
    o.status_period = status_period;
    o.duration = duration;
    deploy::Supervisor supervisor(d, o);
    if (check) {
      std::cout << "deployment " << d.name << " (" << d.services.size() << " services, run dir " << d.run_dir << ")\n";
      for (std::size_t i = 0; i < d.services.size(); ++i) {
        auto argv_s = d.commandLine(i);
        argv_s[0] = supervisor.resolveExec(argv_s[0]);
        std::cout << "  " << d.services[i].name << ":";
        for (const auto& a : argv_s) std::cout << ' ' << a;
        std::cout << '\n';
      }
      return 0;
    }
    const auto& stop = core::installStopSignals();
    const int rc = supervisor.run(stop);
    std::cout << supervisor.summary() << std::flush;
    if (!summary_json.empty()) {
      std::ofstream out(summary_json);
      out << supervisor.summaryJson();
      if (!out) throw std::runtime_error(summary_json + ": cannot write");
    }
    return rc;
  });
}
