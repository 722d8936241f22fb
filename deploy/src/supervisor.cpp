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
#include <thread>

#include "mannequin/core/process.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/subscriber.hpp"

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
double secondsSince(std::int64_t t0) { return (transport::steadyNs() - t0) * 1e-9; }

std::string describeExit(int status) {
  if (WIFEXITED(status)) return fmt::format("exit {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return fmt::format("signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  return "unknown";
}

// The process group of a service (it is its group leader, setpgid in start). The check that a pid ≤ 0
// (a service not running) is never signalled is core::signalProcess's; kNoProcess (it exited since the
// last reap) is fine, the next reap collects it.
const char* signalServiceGroup(pid_t pid, int sig) {
  switch (core::signalProcess(pid, sig, core::SignalTarget::kGroup)) {
    case core::SignalResult::kSent:
    case core::SignalResult::kNoProcess: return nullptr;
    case core::SignalResult::kRefused: return "refused (not a running process)";
    case core::SignalResult::kFailed: return std::strerror(errno);
  }
  return "?";
}
}  // namespace

struct Supervisor::Impl {
  struct Child {
    int fd = -1;                 // read end of its stdout+stderr pipe
    std::string partial;         // incomplete last line
    std::int64_t started_ns = 0;
    std::int64_t restart_at_ns = 0;
    double backoff = 0;
    bool stopping = false;
  };
  std::vector<Child> children;
  zmq::context_t context;
  std::unique_ptr<transport::Subscriber> heartbeats;
  bool status_shown = false;  // tty: a status line is on screen
  std::size_t name_width = 8;
};

Supervisor::Supervisor(Deployment deployment, SupervisorOptions options)
    : impl_(std::make_unique<Impl>()), deployment_(std::move(deployment)), options_(std::move(options)) {
  for (const auto& s : deployment_.services) {
    ServiceStatus st;
    st.name = s.name;
    status_.push_back(st);
    impl_->name_width = std::max(impl_->name_width, s.name.size());
  }
  impl_->children.resize(deployment_.services.size());
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

std::string Supervisor::resolveExec(const std::string& exec) const {
  if (exec.find('/') != std::string::npos) return exec;
  if (!options_.exec_dir.empty()) {
    const auto p = std::filesystem::path(options_.exec_dir) / exec;
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

namespace {
void writeAll(std::FILE* out, const std::string& s) {
  std::fwrite(s.data(), 1, s.size(), out);
  std::fflush(out);
}
}  // namespace

int Supervisor::run(const std::atomic<bool>& stop) {
  std::error_code ec;
  std::filesystem::create_directories(deployment_.run_dir, ec);
  if (ec) {
    writeAll(options_.out, fmt::format("launch: cannot create the run directory {}: {}\n", deployment_.run_dir, ec.message()));
    return 1;
  }
  chmod(deployment_.run_dir.c_str(), 0700);

  // heartbeats of every service
  transport::SubscriberOptions so;
  so.name = "launch";
  impl_->heartbeats = std::make_unique<transport::Subscriber>(impl_->context, so);
  for (const auto& s : deployment_.services) impl_->heartbeats->connect(s.publish);
  impl_->heartbeats->subscribe(
      transport::topics::kHeartbeat,
      std::function<void(const v1::Heartbeat&)>([this](const v1::Heartbeat& hb) {
        for (auto& st : status_)
          if (st.name == hb.service() || st.name == hb.header().source()) {
            st.has_heartbeat = true;
            st.last_heartbeat_ns = transport::steadyNs();
            st.heartbeat = hb;
            ++st.heartbeats;
          }
      }));

  auto clearStatus = [&] {
    if (options_.tty && impl_->status_shown) {
      writeAll(options_.out, "\r\033[K");
      impl_->status_shown = false;
    }
  };
  auto emitLine = [&](std::size_t i, const std::string& line) {
    clearStatus();
    writeAll(options_.out, fmt::format("{:<{}} | {}\n", status_[i].name, impl_->name_width, line));
  };
  auto launcherLine = [&](const std::string& line) {
    clearStatus();
    writeAll(options_.out, fmt::format("{:<{}} | {}\n", "launch", impl_->name_width, line));
  };

  auto start = [&](std::size_t i) {
    const auto argv_s = deployment_.commandLine(i);
    const std::string exe = resolveExec(argv_s[0]);
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) {
      launcherLine(fmt::format("{}: pipe failed: {}", status_[i].name, std::strerror(errno)));
      return;
    }
    std::vector<char*> argv;
    for (const auto& a : argv_s) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid == 0) {
      setpgid(0, 0);
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != parent) _exit(126);  // the launcher died between fork and prctl
      sigset_t none;
      sigemptyset(&none);
      sigprocmask(SIG_SETMASK, &none, nullptr);
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      signal(SIGPIPE, SIG_DFL);
      dup2(fds[1], STDOUT_FILENO);
      dup2(fds[1], STDERR_FILENO);
      int devnull = open("/dev/null", O_RDONLY);
      if (devnull >= 0) dup2(devnull, STDIN_FILENO);
      execv(exe.c_str(), argv.data());
      const std::string msg = fmt::format("cannot execute '{}': {}\n", exe, std::strerror(errno));
      (void)!write(STDERR_FILENO, msg.data(), msg.size());
      _exit(127);
    }
    close(fds[1]);
    if (pid < 0) {
      close(fds[0]);
      launcherLine(fmt::format("{}: fork failed: {}", status_[i].name, std::strerror(errno)));
      return;
    }
    setpgid(pid, pid);
    auto& c = impl_->children[i];
    if (c.fd >= 0) close(c.fd);
    c.fd = fds[0];
    fcntl(c.fd, F_SETFL, O_NONBLOCK);
    c.partial.clear();
    c.started_ns = transport::steadyNs();
    c.stopping = false;
    auto& st = status_[i];
    st.pid = pid;
    st.pids.push_back(pid);
    ++st.starts;
    st.state = ServiceState::kStarting;
    st.has_heartbeat = false;
    st.last_exit.clear();
    std::string cmd;
    for (const auto& a : argv_s) cmd += (cmd.empty() ? "" : " ") + a;
    launcherLine(fmt::format("started {} (pid {}): {}", st.name, pid, cmd));
  };

  auto drain = [&](std::size_t i, bool final) {
    auto& c = impl_->children[i];
    if (c.fd < 0) return;
    char buf[8192];
    for (;;) {
      const ssize_t n = read(c.fd, buf, sizeof(buf));
      if (n > 0) {
        c.partial.append(buf, static_cast<std::size_t>(n));
        std::size_t nl;
        while ((nl = c.partial.find('\n')) != std::string::npos) {
          emitLine(i, c.partial.substr(0, nl));
          c.partial.erase(0, nl + 1);
        }
        continue;
      }
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {  // EOF: the child closed its output
        if (!c.partial.empty()) emitLine(i, c.partial);
        c.partial.clear();
        close(c.fd);
        c.fd = -1;
      }
      break;
    }
    (void)final;
  };

  auto reap = [&](bool shutting_down) {
    int status = 0;
    pid_t pid;
    while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
      for (std::size_t i = 0; i < status_.size(); ++i) {
        auto& st = status_[i];
        if (st.pid != pid) continue;
        drain(i, true);
        auto& c = impl_->children[i];
        st.pid = -1;
        st.last_exit = describeExit(status);
        const bool ok_exit = WIFEXITED(status) && WEXITSTATUS(status) == 0;
        const bool term = WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM && c.stopping;
        if (shutting_down || c.stopping) {
          st.state = ServiceState::kStopped;
          if (!ok_exit && !term) st.clean_exit = false;
          launcherLine(fmt::format("{} stopped ({})", st.name, st.last_exit));
          continue;
        }
        const RestartOptions& r = deployment_.services[i].restart;
        const double ran = secondsSince(c.started_ns);
        if (ran >= r.stable_after) {
          st.restarts = 0;
          c.backoff = 0;
        }
        const bool restart = r.policy == RestartPolicy::kAlways || (r.policy == RestartPolicy::kOnFailure && !ok_exit);
        if (!ok_exit) st.clean_exit = false;
        if (!restart) {
          st.state = ok_exit ? ServiceState::kFinished : ServiceState::kFailed;
          launcherLine(fmt::format("{} {} ({}), not restarted", st.name, ok_exit ? "finished" : "failed", st.last_exit));
          continue;
        }
        if (st.restarts >= r.max_restarts) {
          st.state = ServiceState::kFailed;
          launcherLine(fmt::format("{} exited ({}) after {} restarts: failed permanently", st.name, st.last_exit, st.restarts));
          continue;
        }
        c.backoff = c.backoff == 0 ? r.backoff_initial : std::min(r.backoff_max, 2 * c.backoff);
        c.restart_at_ns = transport::steadyNs() + static_cast<std::int64_t>(c.backoff * 1e9);
        st.state = ServiceState::kBackoff;
        launcherLine(fmt::format("{} exited ({}), restarting in {:.1f} s", st.name, st.last_exit, c.backoff));
      }
    }
  };

  const std::int64_t t0 = transport::steadyNs();
  for (std::size_t i = 0; i < deployment_.services.size(); ++i) start(i);
  publishSnapshot();
  std::int64_t last_status = t0;
  while (!stop.load()) {
    if (options_.duration > 0 && secondsSince(t0) >= options_.duration) {
      launcherLine(fmt::format("duration of {} s reached", options_.duration));
      break;
    }
    // wait for output (or 20 ms)
    std::vector<pollfd> fds;
    for (const auto& c : impl_->children)
      if (c.fd >= 0) fds.push_back({c.fd, POLLIN, 0});
    if (fds.empty())
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    else
      ::poll(fds.data(), fds.size(), 20);
    for (std::size_t i = 0; i < status_.size(); ++i) drain(i, false);
    reap(false);
    impl_->heartbeats->poll(std::chrono::microseconds(0));
    const std::int64_t now = transport::steadyNs();
    for (std::size_t i = 0; i < status_.size(); ++i) {
      auto& st = status_[i];
      auto& c = impl_->children[i];
      if (st.state == ServiceState::kBackoff && now >= c.restart_at_ns) {
        ++st.restarts;
        start(i);
      }
      if (st.pid > 0) {
        if (st.has_heartbeat)
          st.state = (now - st.last_heartbeat_ns) * 1e-9 > deployment_.heartbeat_timeout ? ServiceState::kLate : ServiceState::kUp;
        else if (secondsSince(c.started_ns) > deployment_.heartbeat_timeout)
          st.state = ServiceState::kLate;
      }
    }
    const double period = options_.tty ? 0.25 : options_.status_period;
    if (period > 0 && (now - last_status) * 1e-9 >= period) {
      last_status = now;
      if (options_.tty) {
        clearStatus();
        writeAll(options_.out, statusLineOf(status_));
        impl_->status_shown = true;
      } else {
        writeAll(options_.out, fmt::format("{:<{}} | {}\n", "status", impl_->name_width, statusLineOf(status_)));
      }
    }
    publishSnapshot();
  }

  // shutdown: SIGTERM in reverse order, then SIGKILL after the timeout; reap everything
  clearStatus();
  launcherLine("stopping every service");
  for (std::size_t k = status_.size(); k-- > 0;) {
    auto& st = status_[k];
    if (st.state == ServiceState::kBackoff) st.state = ServiceState::kStopped;
    if (st.pid <= 0) continue;
    impl_->children[k].stopping = true;
    if (const char* error = signalServiceGroup(st.pid, SIGTERM))
      launcherLine(fmt::format("{} (pid {}): SIGTERM {}", st.name, st.pid, error));
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
    impl_->heartbeats->poll(std::chrono::microseconds(0));  // keep the last heartbeats (final statistics)
    for (std::size_t i = 0; i < status_.size(); ++i) drain(i, false);
    reap(true);
    if (!killed && secondsSince(stop_start) > deployment_.stop_timeout) {
      for (auto& st : status_)
        if (st.pid > 0) {
          launcherLine(fmt::format("{} did not stop within {} s: SIGKILL", st.name, deployment_.stop_timeout));
          if (const char* error = signalServiceGroup(st.pid, SIGKILL))
            launcherLine(fmt::format("{} (pid {}): SIGKILL {}", st.name, st.pid, error));
          st.clean_exit = false;
        }
      killed = true;
    }
    publishSnapshot();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  impl_->heartbeats->poll(std::chrono::microseconds(0));
  for (std::size_t i = 0; i < status_.size(); ++i) drain(i, true);
  std::filesystem::remove(deployment_.run_dir, ec);  // only if empty
  publishSnapshot();

  int rc = 0;
  for (const auto& st : status_)
    if (st.state == ServiceState::kFailed || !st.clean_exit) rc = 1;
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
    s += fmt::format("  {:<{}} {:<10} starts {} restarts {} last {} heartbeats {}\n", st.name, impl_->name_width,
                     toString(st.state), st.starts, st.restarts, st.last_exit.empty() ? "-" : st.last_exit, st.heartbeats);
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
                     "\"pids\": [{}], \"heartbeats\": {}",
                     i ? ", " : "", q(st.name), q(toString(st.state)), st.starts, st.restarts, q(st.last_exit),
                     st.clean_exit ? "true" : "false", pids, st.heartbeats);
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
