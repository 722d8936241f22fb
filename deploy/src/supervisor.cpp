#include "mannequin/deploy/supervisor.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

#include "mannequin/deploy/heartbeat_monitor.hpp"
#include "mannequin/deploy/process_backend.hpp"
#include "mannequin/deploy/restart_policy.hpp"
#include "mannequin/deploy/status_printer.hpp"
#include "mannequin/transport/clock.hpp"

namespace mannequin::deploy {

const char* toString(ServiceState s) {
  switch (s) {
    case ServiceState::kStarting: return "starting";
    case ServiceState::kUp: return "up";
    case ServiceState::kLate: return "late";
    case ServiceState::kBackoff: return "restarting";
    case ServiceState::kFinished: return "finished";
    case ServiceState::kFailed: return "failed";
    case ServiceState::kStopped: return "stopped";
  }
  return "?";
}

namespace {
double secondsSince(std::int64_t t0) { return static_cast<double>(transport::steadyNs() - t0) * 1e-9; }
}  // namespace

struct Supervisor::Impl {
  struct Child {
    int fd = -1;                 // read end of its stdout+stderr pipe
    std::string partial;         // incomplete last line
    std::int64_t started_ns = 0;
    std::int64_t restart_at_ns = 0;
    bool stopping = false;
    std::optional<RestartTracker> restarts;
  };
  std::vector<Child> children;
  zmq::context_t context;
  std::unique_ptr<ProcessBackend> backend = std::make_unique<LocalProcessBackend>();
  std::unique_ptr<HeartbeatMonitor> heartbeats;
  std::size_t name_width = 8;
  std::vector<Ended> ended;
};

Supervisor::Supervisor(Deployment deployment, SupervisorOptions options)
    : impl_(std::make_unique<Impl>()), deployment_(std::move(deployment)), options_(std::move(options)) {
  if (deployment_.multiHost() && !deployment_.findHost(options_.host))
    throw std::invalid_argument(deployment_.source + ": " +
                                (options_.host.empty() ? std::string("a multi-host deployment: give the host this launcher runs")
                                                       : "no host '" + options_.host + "'") +
                                " (hosts: " + deployment_.hostNames() + ")");
  if (!deployment_.multiHost() && !options_.host.empty())
    throw std::invalid_argument(deployment_.source + ": a single-host deployment (no 'hosts'): no host '" + options_.host + "' to choose");
  for (std::size_t i = 0; i < deployment_.services.size(); ++i) {
    const ServiceSpec& s = deployment_.services[i];
    ServiceStatus st;
    st.name = s.name;
    st.host = s.host;
    st.local = deployment_.runsOn(i, options_.host);
    status_.push_back(st);
    impl_->name_width = std::max(impl_->name_width, s.name.size());
  }
  impl_->children.resize(deployment_.services.size());
  for (std::size_t i = 0; i < deployment_.services.size(); ++i) impl_->children[i].restarts.emplace(deployment_.services[i].restart);
  snapshot_ = status_;
}

void Supervisor::publishSnapshot() {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  snapshot_ = status_;
}

std::vector<ServiceStatus> Supervisor::status() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return snapshot_;
}

Supervisor::~Supervisor() {
  for (auto& c : impl_->children)
    if (c.fd >= 0) close(c.fd);
}

std::string resolveExecutable(const std::string& exec, const std::string& exec_dir) {
  if (exec.find('/') != std::string::npos) return exec;
  if (!exec_dir.empty()) {
    const auto p = std::filesystem::path(exec_dir) / exec;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  if (const char* path = std::getenv("PATH")) {
    std::string dirs = path;
    std::size_t start = 0;
    while (start <= dirs.size()) {
      const std::size_t end = std::min(dirs.find(':', start), dirs.size());
      const auto p = std::filesystem::path(dirs.substr(start, end - start)) / exec;
      if (access(p.c_str(), X_OK) == 0) return p.string();
      start = end + 1;
    }
  }
  return exec;  // execv fails and the child reports it
}

std::string Supervisor::resolveExec(const std::string& exec) const { return resolveExecutable(exec, options_.exec_dir); }

int Supervisor::run(const std::atomic<bool>& stop) {
  StatusPrinter out(options_.out, options_.tty, impl_->name_width);
  std::error_code ec;
  std::filesystem::create_directories(deployment_.run_dir, ec);
  if (ec) {
    out.launcher(fmt::format("cannot create the run directory {}: {}", deployment_.run_dir, ec.message()));
    return 1;
  }
  chmod(deployment_.run_dir.c_str(), 0700);
  std::vector<std::string> security_files;  // removed at the end
  std::optional<transport::CurveClientOptions> monitor_keys;
  if (deployment_.security) {
    // each local service's keys (--security RUN_DIR/security/NAME.yaml), the monitor's own
    const std::filesystem::path dir = std::filesystem::path(deployment_.run_dir) / "security";
    std::filesystem::create_directories(dir, ec);
    chmod(dir.c_str(), 0700);
    for (std::size_t i = 0; i < deployment_.services.size() && !ec; ++i) {
      if (!status_[i].local) continue;
      const std::string file = deployment_.securityFile(i);
      std::ofstream f(file, std::ios::trunc);
      f << deployment_.securityFileText(i);
      f.close();
      if (!f) {
        out.launcher(fmt::format("cannot write {}", file));
        return 1;
      }
      security_files.push_back(file);
    }
    if (ec) {
      out.launcher(fmt::format("cannot create {}: {}", dir.string(), ec.message()));
      return 1;
    }
    try {
      monitor_keys = deployment_.clientKeys(deployment_.secretKeyFile(Deployment::launcherKeyName(options_.host)));
    } catch (const std::exception& e) {
      out.launcher(fmt::format("the launcher's keys: {}", e.what()));
      return 1;
    }
  }

  // checkpoints (a service's `checkpoint`): one left by a previous run is not resumed from (a launch is
  // a fresh start; only a restart resumes)
  std::vector<std::string> checkpoints;  // removed at the end
  for (std::size_t i = 0; i < deployment_.services.size(); ++i) {
    const std::string& f = deployment_.services[i].checkpoint;
    if (!status_[i].local || f.empty()) continue;
    checkpoints.push_back(f);
    if (std::filesystem::exists(f, ec)) {
      std::filesystem::remove(f, ec);
      out.launcher(fmt::format("{}: removed the checkpoint {} a previous run left (a launch starts fresh)", status_[i].name, f));
    }
  }

  std::vector<std::string> endpoints;  // every service's, this host's and the others' (the whole room)
  for (const auto& s : deployment_.services) endpoints.push_back(s.address);
  impl_->heartbeats = std::make_unique<HeartbeatMonitor>(impl_->context, endpoints, monitor_keys);
  ProcessBackend& backend = *impl_->backend;

  auto start = [&](std::size_t i) {
    // a restart resumes from the checkpoint its previous run left, if any
    const std::string& checkpoint = deployment_.services[i].checkpoint;
    std::error_code exists_ec;
    const bool resume = status_[i].starts > 0 && !checkpoint.empty() && std::filesystem::exists(checkpoint, exists_ec);
    std::vector<std::string> argv = deployment_.commandLine(i, resume);
    std::string cmd;
    for (const auto& a : argv) cmd += (cmd.empty() ? "" : " ") + a;
    argv[0] = resolveExec(argv[0]);
    std::string error;
    const std::optional<Launched> launched = backend.start(argv, error);
    if (!launched) {
      out.launcher(fmt::format("{}: {}", status_[i].name, error));
      return;
    }
    auto& c = impl_->children[i];
    if (c.fd >= 0) close(c.fd);
    c.fd = launched->output_fd;
    c.partial.clear();
    c.started_ns = transport::steadyNs();
    c.stopping = false;
    auto& st = status_[i];
    st.pid = launched->pid;
    st.pids.push_back(launched->pid);
    ++st.starts;
    st.state = ServiceState::kStarting;
    st.has_heartbeat = false;
    st.last_exit.clear();
    out.launcher(fmt::format("started {} (pid {}): {}", st.name, launched->pid, cmd));
  };

  auto drain = [&](std::size_t i) {
    auto& c = impl_->children[i];
    if (c.fd < 0) return;
    char buf[8192];
    for (;;) {
      const ssize_t n = read(c.fd, buf, sizeof(buf));
      if (n > 0) {
        c.partial.append(buf, static_cast<std::size_t>(n));
        std::size_t nl;
        while ((nl = c.partial.find('\n')) != std::string::npos) {
          out.line(status_[i].name, c.partial.substr(0, nl));
          c.partial.erase(0, nl + 1);
        }
        continue;
      }
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {  // EOF: the child closed its output
        if (!c.partial.empty()) out.line(status_[i].name, c.partial);
        c.partial.clear();
        close(c.fd);
        c.fd = -1;
      }
      break;
    }
  };

  auto reap = [&](bool shutting_down) {
    impl_->ended.clear();
    backend.reap(impl_->ended);
    for (const Ended& e : impl_->ended) {
      for (std::size_t i = 0; i < status_.size(); ++i) {
        auto& st = status_[i];
        if (st.pid != e.pid) continue;
        drain(i);
        auto& c = impl_->children[i];
        st.pid = -1;
        st.last_exit = describeExit(e.status);
        const bool ok_exit = WIFEXITED(e.status) && WEXITSTATUS(e.status) == 0;
        const bool term = WIFSIGNALED(e.status) && WTERMSIG(e.status) == SIGTERM && c.stopping;
        if (shutting_down || c.stopping) {
          st.state = ServiceState::kStopped;
          if (!ok_exit && !term) st.clean_exit = false;
          out.launcher(fmt::format("{} stopped ({})", st.name, st.last_exit));
          continue;
        }
        if (!ok_exit) st.clean_exit = false;
        RestartTracker& r = *c.restarts;
        switch (r.onExit(ok_exit, secondsSince(c.started_ns))) {
          case RestartTracker::Decision::kFinished:
          case RestartTracker::Decision::kFailed:
            st.restarts = r.restarts();
            st.state = ok_exit ? ServiceState::kFinished : ServiceState::kFailed;
            out.launcher(fmt::format("{} {} ({}), not restarted", st.name, ok_exit ? "finished" : "failed", st.last_exit));
            break;
          case RestartTracker::Decision::kFailedPermanently:
            st.restarts = r.restarts();
            st.state = ServiceState::kFailed;
            out.launcher(fmt::format("{} exited ({}) after {} restarts: failed permanently", st.name, st.last_exit, r.restarts()));
            break;
          case RestartTracker::Decision::kRestart:
            st.restarts = r.restarts();
            c.restart_at_ns = transport::steadyNs() + static_cast<std::int64_t>(r.backoff() * 1e9);
            st.state = ServiceState::kBackoff;
            out.launcher(fmt::format("{} exited ({}), restarting in {:.1f} s", st.name, st.last_exit, r.backoff()));
            break;
        }
      }
    }
  };

  const std::int64_t t0 = transport::steadyNs();
  for (std::size_t i = 0; i < deployment_.services.size(); ++i) {
    if (status_[i].local)
      start(i);
    else
      impl_->children[i].started_ns = t0;  // another host's: late when no heartbeat within the timeout
  }
  publishSnapshot();
  std::int64_t last_status = t0;
  std::vector<pollfd> fds;
  while (!stop.load()) {
    if (options_.duration > 0 && secondsSince(t0) >= options_.duration) {
      out.launcher(fmt::format("duration of {} s reached", options_.duration));
      break;
    }
    // wait for output (or 20 ms)
    fds.clear();
    for (const auto& c : impl_->children)
      if (c.fd >= 0) fds.push_back({c.fd, POLLIN, 0});
    if (fds.empty())
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    else
      ::poll(fds.data(), fds.size(), 20);
    for (std::size_t i = 0; i < status_.size(); ++i) drain(i);
    reap(false);
    impl_->heartbeats->poll(status_);
    const std::int64_t now = transport::steadyNs();
    for (std::size_t i = 0; i < status_.size(); ++i) {
      auto& st = status_[i];
      auto& c = impl_->children[i];
      if (st.state == ServiceState::kBackoff && now >= c.restart_at_ns) {
        c.restarts->restarted();
        st.restarts = c.restarts->restarts();
        start(i);
      }
      if (st.pid > 0 || !st.local) {
        const ServiceState live = liveness(st.has_heartbeat, st.last_heartbeat_ns, c.started_ns, now, deployment_.heartbeat_timeout);
        if (live != ServiceState::kStarting) st.state = live;
      }
    }
    const double period = options_.tty ? 0.25 : options_.status_period;
    if (period > 0 && static_cast<double>(now - last_status) * 1e-9 >= period) {
      last_status = now;
      out.status(statusLineOf(status_));
    }
    publishSnapshot();
  }

  // shutdown: SIGTERM in reverse order, then SIGKILL after the timeout; reap everything
  out.clear();
  out.launcher("stopping every service");
  for (std::size_t k = status_.size(); k-- > 0;) {
    auto& st = status_[k];
    if (st.state == ServiceState::kBackoff) st.state = ServiceState::kStopped;
    if (st.pid <= 0) continue;
    impl_->children[k].stopping = true;
    if (const char* error = backend.signalGroup(st.pid, SIGTERM))
      out.launcher(fmt::format("{} (pid {}): SIGTERM {}", st.name, st.pid, error));
  }
  publishSnapshot();
  const std::int64_t stop_start = transport::steadyNs();
  auto anyRunning = [&] {
    for (const auto& st : status_)
      if (st.pid > 0) return true;
    return false;
  };
  bool killed = false;
  while (anyRunning()) {
    impl_->heartbeats->poll(status_);  // keep the last heartbeats (final statistics)
    for (std::size_t i = 0; i < status_.size(); ++i) drain(i);
    reap(true);
    if (!killed && secondsSince(stop_start) > deployment_.stop_timeout) {
      for (auto& st : status_)
        if (st.pid > 0) {
          out.launcher(fmt::format("{} did not stop within {} s: SIGKILL", st.name, deployment_.stop_timeout));
          if (const char* error = backend.signalGroup(st.pid, SIGKILL))
            out.launcher(fmt::format("{} (pid {}): SIGKILL {}", st.name, st.pid, error));
          st.clean_exit = false;
        }
      killed = true;
    }
    publishSnapshot();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  impl_->heartbeats->poll(status_);
  for (std::size_t i = 0; i < status_.size(); ++i) drain(i);
  for (const std::string& f : security_files) std::filesystem::remove(f, ec);
  for (const std::string& f : checkpoints) {
    std::filesystem::remove(f, ec);
    std::filesystem::remove(f + ".tmp", ec);
  }
  if (deployment_.security) std::filesystem::remove(std::filesystem::path(deployment_.run_dir) / "security", ec);
  std::filesystem::remove(deployment_.run_dir, ec);  // only if empty
  publishSnapshot();

  int rc = 0;
  for (const auto& st : status_)
    if (st.local && (st.state == ServiceState::kFailed || !st.clean_exit)) rc = 1;
  return rc;
}


std::string Supervisor::statusLine() const { return statusLineOf(status()); }

std::string Supervisor::statusLineOf(const std::vector<ServiceStatus>& all) {
  int up = 0;
  for (const auto& st : all) up += st.state == ServiceState::kUp;
  std::string line = fmt::format("{}/{} up", up, all.size());
  for (const auto& st : all) {
    line += fmt::format(" | {} {}", st.name, st.state == ServiceState::kUp ? "" : std::string(toString(st.state)) + " ");
    if (!st.has_heartbeat) continue;
    const auto& hb = st.heartbeat;
    line += fmt::format("{:.0f} Hz", hb.loop_rate_hz());
    for (const auto& t : hb.topics())
      if (t.published()) line += fmt::format(", {} {:.1f} Hz", t.topic(), t.rate_hz());
    if (hb.worst_lateness_ms() > 0) line += fmt::format(", late {:.1f} ms", hb.worst_lateness_ms());
    if (hb.state() == v1::SERVICE_STATE_DEGRADED) line += " DEGRADED";
    if (hb.state() == v1::SERVICE_STATE_FINISHED) line += " finished";
  }
  return line;
}

std::string Supervisor::summary() const {
  const std::vector<ServiceStatus> all = status();
  std::string s = fmt::format("summary of deployment '{}' ({})\n", deployment_.name, deployment_.source);
  for (const auto& st : all) {
    if (st.local)
      s += fmt::format("  {:<{}} {:<10} starts {} restarts {} last {} heartbeats {}{}\n", st.name, impl_->name_width,
                       toString(st.state), st.starts, st.restarts, st.last_exit.empty() ? "-" : st.last_exit, st.heartbeats,
                       st.host.empty() ? std::string() : " (host " + st.host + ")");
    else
      s += fmt::format("  {:<{}} {:<10} on host {} (not started here) heartbeats {}\n", st.name, impl_->name_width,
                       toString(st.state), st.host, st.heartbeats);
    if (!st.has_heartbeat) continue;
    const auto& hb = st.heartbeat;
    s += fmt::format("  {:<{}} loop {:.1f} Hz, worst lateness {:.2f} ms, uptime {:.1f} s\n", "", impl_->name_width,
                     hb.loop_rate_hz(), hb.worst_lateness_ms(), hb.uptime_s());
    for (const auto& t : hb.topics())
      s += fmt::format("  {:<{}} {} {:<18} {:>8} msgs {:>7.1f} Hz  dropped {}  malformed {}\n", "", impl_->name_width,
                       t.published() ? "pub" : "sub", t.topic(), t.messages(), t.rate_hz(), t.dropped(), t.malformed());
    if (hb.stats_size() > 0) {
      std::string stats;
      for (const auto& x : hb.stats()) stats += fmt::format("{}{} {:.6g}", stats.empty() ? "" : ", ", x.name(), x.value());
      s += fmt::format("  {:<{}} {}\n", "", impl_->name_width, stats);
    }
  }
  return s;
}

std::string Supervisor::summaryJson() const {
  auto q = [](const std::string& x) {
    std::string o = "\"";
    for (char c : x) {
      if (c == '"' || c == '\\')
        o += '\\', o += c;
      else if (static_cast<unsigned char>(c) < 0x20)
        o += fmt::format("\\u{:04x}", static_cast<int>(c));
      else
        o += c;
    }
    return o + "\"";
  };
  auto num = [](double v) { return std::isfinite(v) ? fmt::format("{}", v) : std::string("null"); };
  const std::vector<ServiceStatus> all = status();
  std::string s = fmt::format("{{\"deployment\": {}, \"services\": [", q(deployment_.name));
  for (std::size_t i = 0; i < all.size(); ++i) {
    const auto& st = all[i];
    std::string pids;
    for (pid_t p : st.pids) pids += (pids.empty() ? "" : ", ") + std::to_string(p);
    s += fmt::format("{}{{\"name\": {}, \"state\": {}, \"starts\": {}, \"restarts\": {}, \"last_exit\": {}, \"clean_exit\": {}, "
                     "\"pids\": [{}], \"heartbeats\": {}, \"host\": {}, \"local\": {}",
                     i ? ", " : "", q(st.name), q(toString(st.state)), st.starts, st.restarts, q(st.last_exit),
                     st.clean_exit ? "true" : "false", pids, st.heartbeats, q(st.host), st.local ? "true" : "false");
    if (st.has_heartbeat) {
      const auto& hb = st.heartbeat;
      s += fmt::format(", \"loop_rate_hz\": {}, \"worst_lateness_ms\": {}, \"topics\": [", num(hb.loop_rate_hz()),
                       num(hb.worst_lateness_ms()));
      for (int k = 0; k < hb.topics_size(); ++k) {
        const auto& t = hb.topics(k);
        s += fmt::format("{}{{\"topic\": {}, \"published\": {}, \"messages\": {}, \"rate_hz\": {}, \"dropped\": {}, \"malformed\": {}}}",
                         k ? ", " : "", q(t.topic()), t.published() ? "true" : "false", t.messages(), num(t.rate_hz()),
                         t.dropped(), t.malformed());
      }
      s += "], \"stats\": {";
      for (int k = 0; k < hb.stats_size(); ++k) s += fmt::format("{}{}: {}", k ? ", " : "", q(hb.stats(k).name()), num(hb.stats(k).value()));
      s += "}";
    }
    s += "}";
  }
  return s + "]}\n";
}

}  // namespace mannequin::deploy
