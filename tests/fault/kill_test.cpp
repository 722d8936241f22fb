// kill -9 of each service of a single-host cluster started by mannequin-launch (mocap playing the shipped
// capture, collision, sim, a headless render node on sim.world), one after the other, while the test
// watches sim.world and every service's heartbeats like a render node and the launcher would:
// - the launcher restarts each (a new pid heartbeats; `restarts` 1 each in --summary-json) and the others
//   go on (same pids, sim.world keeps coming while the killed one is away);
// - render node killed: the sim's step rate within 20 % of what it was before (heartbeats' loop rate);
// - collision killed: sim.world says contacts_stale while it is away and not once it is back, the
//   mannequin's state stays finite and standing (pelvis between 0.5 and 1.5 m);
// - mocap killed: the sim holds the targets (they stop moving while no frame comes), counts the stream gap
//   (when the targets stood still longer than occlusion.hold: the sim's clock may lag behind the capture's
//   by up to reanchor_threshold, 0.5 s, and play received frames meanwhile) and, when the restarted mocap's
//   frames come (their capture clock restarted), a capture restart, and follows the capture again (mocap frame
//   numbers advancing in sim.world) without throwing the mannequin.
// Every wait has a deadline and fails naming what it waited for; no pid ≤ 0 is signalled.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "../common/child_process.hpp"
#include "../common/tool_run.hpp"
#include "mannequin/core/process.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/transport/topics.hpp"

using namespace mannequin;
using Clock = std::chrono::steady_clock;

namespace {

struct Beat {
  Clock::time_point at;
  v1::Heartbeat hb;
};
struct World {
  Clock::time_point at;
  v1::WorldState ws;
};

// The cluster under test and everything the test has seen of it.
class Cluster {
 public:
  explicit Cluster(const std::filesystem::path& dir) : dir_(dir), run_(dir / "run") {
    std::filesystem::create_directories(run_);
    std::ofstream(dir / "fault.yaml") << R"(name: fault
heartbeat_timeout: 2.0
stop_timeout: 3.0
restart: {policy: on-failure, max_restarts: 5, backoff_initial: 0.5, backoff_max: 8.0, stable_after: 10}
services:
  - name: mocap
    exec: mannequin-mocap
    args: [--config, configs/sim/mocap_demo.yaml, --heartbeat-period, "0.2"]
    publish: ipc://${RUN_DIR}/mocap
  - name: collision
    exec: mannequin-collision
    args: [--config, configs/sim/collision_demo.yaml, --heartbeat-period, "0.2"]
    publish: ipc://${RUN_DIR}/collision
    connect: [sim]
  - name: sim
    exec: mannequin-sim
    args: [--config, configs/sim/sim_demo.yaml, --heartbeat-period, "0.2"]
    publish: ipc://${RUN_DIR}/sim
    connect: [mocap, collision]
  - name: view
    exec: mannequin-render
    args: [--view, configs/views/desktop.yaml, --sim, configs/sim/sim_demo.yaml, --headless, --size, 160x90, --every, "120",
           --out, "${RUN_DIR}/frames"]
    publish: ipc://${RUN_DIR}/view
    connect: [sim]
)";
    launcher_ = std::make_unique<testutil::Child>(
        std::vector<std::string>{(testutil::binDir() / "mannequin-launch").string(), (dir / "fault.yaml").string(), "--run-dir",
                                 run_.string(), "--status-period", "0.5", "--no-tty", "--summary-json", summary().string()},
        log().string());
    std::vector<std::string> eps;
    for (const char* s : {"mocap", "collision", "sim", "view"}) eps.push_back("ipc://" + (run_ / s).string());
    sub_ = std::make_unique<transport::Subscriber>(ctx_, transport::SubscriberOptions{"fault-test", eps});
    sub_->subscribe(transport::topics::kHeartbeat,
                    std::function<void(const v1::Heartbeat&)>([this](const v1::Heartbeat& h) { beats_.push_back({Clock::now(), h}); }));
    sub_->subscribe(transport::topics::kSimWorld,
                    std::function<void(const v1::WorldState&)>([this](const v1::WorldState& w) { worlds_.push_back({Clock::now(), w}); }));
  }
  bool started() const { return launcher_->started(); }
  std::filesystem::path log() const { return dir_ / "launch.log"; }
  std::filesystem::path summary() const { return dir_ / "summary.json"; }
  int stop() { return launcher_->stop(std::chrono::seconds(30)); }

  /// Polls until `done()` or `timeout`; false (and a failure naming `what`, with the launcher's log) at the deadline.
  bool until(const std::string& what, std::chrono::seconds timeout, const std::function<bool()>& done) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
      if (Clock::now() >= deadline) {
        ADD_FAILURE() << "within " << timeout.count() << " s: " << what << "\n" << testutil::slurp(log());
        return false;
      }
      sub_->poll(std::chrono::milliseconds(10));
    }
    return true;
  }
  /// Polls for `d`, collecting.
  void watch(std::chrono::milliseconds d) {
    const auto end = Clock::now() + d;
    while (Clock::now() < end) sub_->poll(std::chrono::milliseconds(10));
  }
  /// The pid of the newest heartbeat of `service` (0: none yet).
  int pid(const std::string& service) const {
    for (auto it = beats_.rbegin(); it != beats_.rend(); ++it)
      if (it->hb.service() == service) return it->hb.pid();
    return 0;
  }
  /// kill -9 of the service's current pid (checked > 0); the pid killed.
  int kill9(const std::string& service) {
    const int p = pid(service);
    EXPECT_GT(p, 0) << service;
    EXPECT_EQ(core::signalProcess(p, SIGKILL), core::SignalResult::kSent) << service << " pid " << p;
    return p;
  }
  /// Waits for a heartbeat of `service` from another pid than `old`: the restarted process.
  bool restarted(const std::string& service, int old, std::chrono::seconds timeout) {
    return until(service + " restarted (a heartbeat from a pid other than " + std::to_string(old) + ")", timeout,
                 [&] { return pid(service) > 0 && pid(service) != old; });
  }
  /// The sim's loop rates (Hz) of its heartbeats received in [from, to).
  std::vector<double> simRates(Clock::time_point from, Clock::time_point to) const {
    std::vector<double> r;
    for (const Beat& b : beats_)
      if (b.hb.service() == "sim" && b.at >= from && b.at < to && b.hb.loop_rate_hz() > 0) r.push_back(b.hb.loop_rate_hz());
    return r;
  }
  /// The sim's worst lateness (ms) over its heartbeats received in [from, to), and its last `overruns` stat there.
  std::pair<double, double> simLateness(Clock::time_point from, Clock::time_point to) const {
    double worst = 0, overruns = -1;
    for (const Beat& b : beats_)
      if (b.hb.service() == "sim" && b.at >= from && b.at < to) {
        worst = std::max(worst, b.hb.worst_lateness_ms());
        for (const auto& st : b.hb.stats())
          if (st.name() == "overruns") overruns = st.value();
      }
    return {worst, overruns};
  }
  /// The fastest joint (rad/s, not the floating base) of the sim.world states [from, to).
  double fastestJoint(std::size_t from, std::size_t to) const {
    double v = 0;
    for (std::size_t i = from; i < to && i < worlds_.size(); ++i)
      for (int k = 6; k < worlds_[i].ws.mannequins(0).v_size(); ++k) v = std::max(v, std::abs(worlds_[i].ws.mannequins(0).v(k)));
    return v;
  }
  /// How many sim.world arrived in [from, to).
  std::size_t worldsBetween(Clock::time_point from, Clock::time_point to) const {
    return static_cast<std::size_t>(std::count_if(worlds_.begin(), worlds_.end(), [&](const World& w) { return w.at >= from && w.at < to; }));
  }
  /// The longest interval between two sim.world received in [from, to) (s).
  double longestWorldGap(Clock::time_point from, Clock::time_point to) const {
    double gap = 0;
    Clock::time_point last = from;
    for (const World& w : worlds_)
      if (w.at >= from && w.at < to) {
        gap = std::max(gap, std::chrono::duration<double>(w.at - last).count());
        last = w.at;
      }
    return std::max(gap, std::chrono::duration<double>(to - last).count());
  }
  const std::vector<World>& worlds() const { return worlds_; }

 private:
  std::filesystem::path dir_, run_;
  zmq::context_t ctx_;
  std::unique_ptr<testutil::Child> launcher_;
  std::unique_ptr<transport::Subscriber> sub_;
  std::vector<Beat> beats_;
  std::vector<World> worlds_;
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The entry of `service` in the launcher's --summary-json (up to the next entry).
std::string entryOf(const std::string& json, const std::string& service) {
  const auto at = json.find("{\"name\": \"" + service + "\"");
  if (at == std::string::npos) return {};
  return json.substr(at, json.find("{\"name\": ", at + 1) - at);
}

bool finiteState(const v1::WorldState& w) {
  for (const auto& m : w.mannequins()) {
    for (double x : m.q())
      if (!std::isfinite(x)) return false;
    for (double x : m.v())
      if (!std::isfinite(x)) return false;
  }
  return true;
}

}  // namespace

TEST(FaultCluster, KillNineOfEachServiceIsRestartedWithBackoffAndTheOthersGoOn) {
  const testutil::TempDir dir("FaultCluster");
  ASSERT_FALSE(dir.path().empty());
  Cluster c(dir.path());
  ASSERT_TRUE(c.started());
  // every service heartbeating, the mannequin calibrated and sim.world flowing
  ASSERT_TRUE(c.until("every service heartbeating and a calibrated mannequin in sim.world", std::chrono::seconds(60), [&] {
    return c.pid("mocap") > 0 && c.pid("collision") > 0 && c.pid("sim") > 0 && c.pid("view") > 0 && !c.worlds().empty() &&
           c.worlds().back().ws.mannequins_size() == 1 && c.worlds().back().ws.mannequins(0).calibrated();
  }));
  c.watch(std::chrono::milliseconds(2000));
  const int sim_pid = c.pid("sim");

  // ---- the render node: the sim does not notice
  {
    const auto before = Clock::now();
    c.watch(std::chrono::milliseconds(3000));
    const auto killed_at = Clock::now();
    const int old = c.kill9("view");
    ASSERT_TRUE(c.restarted("view", old, std::chrono::seconds(30)));
    const auto back_at = Clock::now();
    c.watch(std::chrono::milliseconds(1000));
    const auto after = Clock::now();
    const double rate_before = median(c.simRates(before, killed_at)), rate_during = median(c.simRates(killed_at, after));
    const auto late_before = c.simLateness(before, killed_at), late_during = c.simLateness(killed_at, after);
    std::printf("render node killed: sim step rate %.0f Hz before, %.0f Hz until it was back; worst lateness %.2f ms before, %.2f ms "
                "during (overruns %.0f, %.0f); longest sim.world gap %.3f s\n",
                rate_before, rate_during, late_before.first, late_during.first, late_before.second, late_during.second,
                c.longestWorldGap(killed_at, after));
    EXPECT_GT(rate_during, 0.8 * rate_before);
    // sim.world went on while the node was away (down ≥ the 0.5 s backoff: ≥ 30 states at 60 Hz; 10 leaves room
    // for the stalls of a loaded machine, whose lengths are printed, not asserted)
    EXPECT_GE(c.worldsBetween(killed_at, back_at), 10u);
    EXPECT_EQ(c.pid("sim"), sim_pid);
  }

  // ---- collision: contacts flagged stale while it is away, the mannequin held safe
  {
    const std::size_t from = c.worlds().size();
    const int old = c.kill9("collision");
    const auto killed_at = Clock::now();
    ASSERT_TRUE(c.restarted("collision", old, std::chrono::seconds(30)));
    const auto restarted_at = Clock::now();
    const std::size_t back_at = c.worlds().size();
    ASSERT_TRUE(c.until("sim.world with fresh contacts again after collision's restart", std::chrono::seconds(20), [&] {
      return c.worlds().size() > back_at && !c.worlds().back().ws.contacts_stale();
    }));
    std::size_t stale = 0;
    bool finite = true;
    double low = 1e9, high = -1e9;
    for (std::size_t i = from; i < c.worlds().size(); ++i) {
      const v1::WorldState& w = c.worlds()[i].ws;
      stale += w.contacts_stale();
      finite = finite && finiteState(w);
      for (const auto& cf : w.mannequins(0).control_frames())
        if (cf.frame() == "pelvis") low = std::min(low, cf.actual().position().z()), high = std::max(high, cf.actual().position().z());
    }
    std::printf("collision killed: %zu of %zu sim.world contacts_stale, pelvis height %.3f..%.3f m, longest sim.world gap %.3f s\n", stale,
                c.worlds().size() - from, low, high, c.longestWorldGap(killed_at, Clock::now()));
    EXPECT_GT(stale, 0u) << "sim.world never said contacts_stale while collision was away";
    EXPECT_TRUE(finite);
    EXPECT_GT(low, 0.5);
    EXPECT_LT(high, 1.5);
    EXPECT_GE(c.worldsBetween(killed_at, restarted_at), 10u);
    EXPECT_EQ(c.pid("sim"), sim_pid);
  }

  // ---- mocap: the sim holds the targets, counts the gap and the restarted capture clock, follows again
  {
    const std::size_t from = c.worlds().size();
    const v1::MocapGlitches g0 = c.worlds().back().ws.mocap_glitches();
    const int old = c.kill9("mocap");
    const auto killed_at = Clock::now();
    ASSERT_TRUE(c.restarted("mocap", old, std::chrono::seconds(30)));
    const auto restarted_at = Clock::now();
    ASSERT_TRUE(c.until("sim.world counting the restarted capture clock", std::chrono::seconds(20), [&] {
      return c.worlds().back().ws.mocap_glitches().capture_restarts() > g0.capture_restarts();
    }));
    const std::size_t back = c.worlds().size();
    c.watch(std::chrono::milliseconds(2000));
    const double fastest_before = c.fastestJoint(0, from), fastest_after = c.fastestJoint(back, c.worlds().size());
    // while no frame came (the mocap FrameRef unchanged), the targets first play out the frames already
    // received (the sim's clock runs behind the capture clock by the interpolation delay and a drift below
    // reanchor_threshold), then stop: once they stopped moving they do not move again until a frame comes
    std::size_t held = 0, moving = 0, frozen = 0, moved_after_frozen = 0;
    bool finite = true;
    for (std::size_t i = from + 1; i < c.worlds().size(); ++i) {
      const v1::WorldState &a = c.worlds()[i - 1].ws, &b = c.worlds()[i].ws;
      finite = finite && finiteState(b);
      if (a.mocap().sequence() != b.mocap().sequence() || a.mocap().stamp_ns() != b.mocap().stamp_ns()) {
        if (held > 0) break;  // the first frame of the restarted mocap
        continue;
      }
      ++held;
      double motion = 0;
      for (int k = 0; k < b.mannequins(0).control_frames_size(); ++k) {
        const auto &p = a.mannequins(0).control_frames(k).target().position(), &q = b.mannequins(0).control_frames(k).target().position();
        motion = std::max(motion, std::hypot(p.x() - q.x(), p.y() - q.y(), p.z() - q.z()));
      }
      if (motion == 0) {
        ++frozen;
      } else {
        ++moving;
        moved_after_frozen += frozen > 0;
      }
    }
    for (std::size_t i = from + 1; i < c.worlds().size(); ++i) finite = finite && finiteState(c.worlds()[i].ws);
    const v1::WorldState& last = c.worlds().back().ws;
    std::printf("mocap killed: %zu sim.world with no new frame: targets moving in the first %zu (frames already received), then "
                "still in %zu; stream gaps %llu -> %llu, capture "
                "restarts %llu -> %llu; longest sim.world gap %.3f s; fastest joint %.1f rad/s before the kill, %.1f rad/s in the 2 s after the "
                "frames came back\n",
                held, moving, frozen, static_cast<unsigned long long>(g0.stream_gaps()),
                static_cast<unsigned long long>(last.mocap_glitches().stream_gaps()), static_cast<unsigned long long>(g0.capture_restarts()),
                static_cast<unsigned long long>(last.mocap_glitches().capture_restarts()), c.longestWorldGap(killed_at, Clock::now()),
                fastest_before, fastest_after);
    EXPECT_GT(held, 10u) << "sim.world went on while mocap was away";
    EXPECT_EQ(moved_after_frozen, 0u) << "the targets moved again without a frame";
    if (frozen >= 21) {  // still for ≥ 0.35 s of states at 60 Hz: longer than occlusion.hold (0.3 s)
      EXPECT_GT(last.mocap_glitches().stream_gaps(), g0.stream_gaps());
    }
    // no explosion when the frames come back: no joint 3 times as fast as the capture itself made them before
    // (unhandled, such a return reached 4–8 times, 127–280 rad/s; handled it measured 0.8–1.5 times, which is
    // too close to a tighter bound to tell reliably: docs/cluster.md "Faults")
    EXPECT_LT(fastest_after, 3.0 * fastest_before);
    EXPECT_TRUE(finite);
    EXPECT_GE(c.worldsBetween(killed_at, restarted_at), 10u);
    EXPECT_GT(last.mocap().frame_number(), c.worlds()[back].ws.mocap().frame_number()) << "the sim does not follow the restarted capture";
    EXPECT_EQ(c.pid("sim"), sim_pid);
  }

  // ---- the sim itself: restarted, sim.world resumes from the new process
  {
    const int old = c.kill9("sim");
    ASSERT_TRUE(c.restarted("sim", old, std::chrono::seconds(30)));
    const std::size_t n = c.worlds().size();
    ASSERT_TRUE(c.until("sim.world from the restarted sim", std::chrono::seconds(30), [&] { return c.worlds().size() > n + 60; }));
  }

  ASSERT_EQ(c.stop(), 1) << "the launcher's exit code: 1, services were killed\n" << testutil::slurp(c.log());
  const std::string json = testutil::slurp(c.summary());
  for (const char* s : {"mocap", "collision", "sim", "view"}) {
    const std::string e = entryOf(json, s);
    EXPECT_NE(e.find("\"starts\": 2, \"restarts\": 1"), std::string::npos) << e;
  }
}
