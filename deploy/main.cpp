// mannequin-launch: runs the services of a deployment file on this host (see docs/cluster.md).
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>

#include "mannequin/core/config.hpp"
#include "mannequin/core/main.hpp"
#include "mannequin/deploy/supervisor.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-launch: starts the services of a deployment file on this host (multi-host: those of\n"
               "--host), prefixes their output, shows a status line from the heartbeats of every service of the\n"
               "deployment (services up, rates, lateness), restarts a crashed service with backoff, and stops all\n"
               "cleanly on Ctrl-C / SIGTERM / --duration. A bad deployment file is FILE:LINE and exit 2."};
  std::string file, run_dir, summary_json, status_json, host, key_dir;
  double duration = 0, status_period = 5.0;
  bool check = false, no_tty = false;
  app.add_option("deployment", file, "deployment file (YAML), e.g. configs/deployments/single-host.yaml")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--host", host, "multi-host deployment: the host this launcher runs (its services are started here)");
  app.add_option("--key-dir", key_dir, "directory of the CURVE key files, instead of the deployment's security.key_dir");
  app.add_option("--duration", duration, "stop everything after this many seconds (0: until Ctrl-C/SIGTERM)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--run-dir", run_dir, "directory of the ipc sockets (${RUN_DIR}); default from the file");
  app.add_option("--status-period", status_period, "seconds between status lines when not on a terminal (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-tty", no_tty, "print status lines instead of one live line even on a terminal");
  app.add_option("--summary-json", summary_json, "also write the final summary as JSON to this file");
  app.add_option("--status-json", status_json,
                 "keep the live status in this file, the --summary-json format, rewritten (FILE.tmp renamed) every "
                 "status period (1 s if 0): for monitoring tools (tools/soak)");
  app.add_flag("--check", check,
               "read and check the deployment, print the command lines (multi-host without --host: every host's), "
               "start nothing");
  return core::runMain(app, argc, argv, [&] {
    const std::string exec_dir = std::filesystem::canonical("/proc/self/exe").parent_path().string();
    std::optional<deploy::Deployment> loaded;
    try {
      loaded = deploy::loadDeployment(file, run_dir);
      if (loaded->multiHost() && !host.empty() && !loaded->findHost(host))
        throw core::ConfigError(file + ": --host " + host + ": no such host (hosts: " + loaded->hostNames() + ")");
      if (!loaded->multiHost() && !host.empty())
        throw core::ConfigError(file + ": --host " + host + ": a single-host deployment has no 'hosts'");
      if (loaded->multiHost() && host.empty() && !check)
        throw core::ConfigError(file + ": a multi-host deployment: give --host NAME (hosts: " + loaded->hostNames() + ")");
      if (!key_dir.empty()) {
        if (!loaded->security) throw core::ConfigError(file + ": --key-dir: this deployment has no 'security'");
        loaded->security->key_dir = std::filesystem::absolute(key_dir).lexically_normal().string();
      }
      deploy::checkKeys(*loaded, host);  // this host's secrets (--check without --host: every host's)
    } catch (const core::ConfigError& e) {
      std::cerr << "mannequin-launch: " << e.what() << '\n';
      return core::kExitUsage;
    }
    const deploy::Deployment& d = *loaded;
    if (check) {
      std::cout << "deployment " << d.name << " (" << d.services.size() << " services, run dir " << d.run_dir << ")\n";
      if (d.security) std::cout << "  security: CURVE, keys in " << d.security->key_dir << " (checked)\n";
      for (const auto& h : d.hosts) std::cout << "  host " << h.name << " at " << h.address << (h.name == host ? " (this host)" : "") << '\n';
      for (std::size_t i = 0; i < d.services.size(); ++i) {
        const deploy::ServiceSpec& s = d.services[i];
        auto argv_s = d.commandLine(i);
        argv_s[0] = deploy::resolveExecutable(argv_s[0], exec_dir);
        std::cout << "  " << s.name;
        if (d.multiHost()) std::cout << " @" << s.host;
        if (s.address != s.publish) std::cout << " (reached at " << s.address << ")";
        if (!host.empty() && !d.runsOn(i, host)) {
          std::cout << ": not started here\n";
          continue;
        }
        std::cout << ":";
        for (const auto& a : argv_s) std::cout << ' ' << a;
        std::cout << '\n';
      }
      return 0;
    }
    deploy::SupervisorOptions o;
    o.exec_dir = exec_dir;
    o.tty = !no_tty && isatty(STDOUT_FILENO);
    o.status_period = status_period;
    o.duration = duration;
    o.host = host;
    deploy::Supervisor supervisor(d, o);
    const auto& stop = core::installStopSignals();
    // --status-json: the snapshot (Supervisor::status is thread-safe) written from its own thread
    std::atomic<bool> run_done{false};
    std::thread status_writer;
    if (!status_json.empty())
      status_writer = std::thread([&] {
        const auto period = std::chrono::duration<double>(status_period > 0 ? status_period : 1.0);
        auto next = std::chrono::steady_clock::now();
        bool warned = false;
        while (!run_done.load()) {
          if (std::chrono::steady_clock::now() >= next) {
            next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
            const std::string tmp = status_json + ".tmp";
            std::ofstream out(tmp, std::ios::trunc);
            out << supervisor.summaryJson();
            out.close();
            std::error_code ec;
            if (out) std::filesystem::rename(tmp, status_json, ec);
            if ((!out || ec) && !warned) {
              warned = true;
              std::cerr << "mannequin-launch: --status-json " << status_json << ": cannot write\n";
            }
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
      });
    const int rc = supervisor.run(stop);
    run_done = true;
    if (status_writer.joinable()) status_writer.join();
    std::cout << supervisor.summary() << std::flush;
    if (!summary_json.empty()) {
      std::ofstream out(summary_json);
      out << supervisor.summaryJson();
      if (!out) throw std::runtime_error(summary_json + ": cannot write");
    }
    return rc;
  });
}
