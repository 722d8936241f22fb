#include "mannequin/simservice/sim_service.hpp"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <algorithm>
#include <deque>

#include "mannequin/service/runtime.hpp"
#include "mannequin/simservice/checkpoint.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/sim/run_totals.hpp"
#include "mannequin/sim/step_driver.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/health.hpp"
#include "mannequin/transport/validate.hpp"

namespace mannequin::simservice {

using namespace std::chrono;
namespace topics = transport::topics;

struct SimService::Impl {
  SimServiceConfig config;
  sim::World world;
  transport::Publisher pub;
  transport::Subscriber sub;
  transport::HealthReporter health;
  SimStats stats;
  std::deque<v1::MocapFrame> pending;  // replay: frames not yet stepped to
  std::vector<std::string> world_sources;  // World::mocapSources(): the sources some mannequin uses ("" first)
  std::uint64_t unused_source_frames = 0;  // frames of a listed source no mannequin uses
  // Status line and stop summary (physics on): contacts, penetration, balance, over the status period and
  // the run; the per-mannequin vectors are sized at construction (nothing allocated per step).
  sim::RunTotals period, run_totals;
  std::int64_t last_status_ns = 0;
  bool new_mocap = false;
  std::int64_t step_ns;
  sim::RateDivider world_rate;  // sim.world at world_rate (exact average rate)
  sim::StepDriver driver;       // frames in, steps to their capture time (replay), one paced step (live)
  const std::atomic<bool>* stop_flag = nullptr;  // run()'s, for the driver's hooks
  // collision lockstep
  v1::ContactSet contacts;
  bool has_contacts = false;
  bool stale = false;
  bool awaiting = false;
  std::uint64_t awaited_step = 0;
  std::int64_t query_sent_ns = 0;
  v1::WorldState world_msg;
  v1::CollisionQuery query_msg;
  // the scenario (config key `scenario`): timed triggers, scenario.state at state_rate and at switches
  TriggerSchedule schedule;
  v1::ScenarioState scenario_msg;
  ScenarioWatch watch;
  // the checkpoint (--checkpoint): written by its own thread, at most every checkpoint_period s
  std::unique_ptr<CheckpointWriter> checkpoint_writer;
  v1::SimCheckpoint checkpoint_msg;
  std::int64_t last_checkpoint_ns = 0;
  std::uint64_t checkpoint_failures_logged = 0;

  Impl(const SimServiceConfig& c, zmq::context_t& ctx, double hb)
      : config(c),
        world(buildMannequins(c), c.world),
        pub(ctx, transport::PublisherOptions{c.name, c.publish, 1000, c.mode == Mode::kReplay, c.curve_server}),
        sub(ctx, transport::SubscriberOptions{c.name, subscriberEndpoints(c), c.mode == Mode::kReplay ? 100000 : 1000, 10000,
                                              c.curve_client}),
        health(pub, c.name, &sub, hb),
        world_rate(c.world_rate, c.world.step),
        driver(world),
        schedule(config.scenario.triggers),
        watch(config.scenario.state_rate, config.world.step) {
    driver.setHooks({[this] { return stop_flag == nullptr || !stop_flag->load(); },
                     [this] {
                       collisionBeforeStep(*stop_flag);
                       schedule.due(world);
                     },
                     [this](bool ok) { afterStep(ok); }});
    setupScenario(world, config);
    if (!config.resume.empty()) resume();
    if (!config.checkpoint.empty()) checkpoint_writer = std::make_unique<CheckpointWriter>(config.checkpoint);
    world_sources = world.mocapSources();
    period.reset(world.numMannequins());
    run_totals.reset(world.numMannequins());
    step_ns = static_cast<std::int64_t>(std::llround(c.world.step * 1e9));
    sub.subscribe(topics::kMocapFrame, std::function<void(const v1::MocapFrame&)>([this](const v1::MocapFrame& f) { onMocap(f); }),
                  transport::validateMocapFrame);
    sub.subscribe(topics::kCollisionContacts,
                  std::function<void(const v1::ContactSet&)>([this](const v1::ContactSet& s) { onContacts(s); }),
                  transport::validateContactSet);
    if (world.scenarioEngine() != nullptr)
      sub.subscribe(topics::kScenarioTrigger,
                    std::function<void(const v1::Trigger&)>([this](const v1::Trigger& t) { onTrigger(t); }),
                    transport::validateTrigger);
  }

  // --resume FILE: the World put back as the checkpoint has it; a checkpoint that cannot be read or does
  // not fit this World is refused (logged) and the sim starts fresh.
  void resume() {
    try {
      const v1::SimCheckpoint c = readCheckpoint(config.resume);
      const std::vector<std::string> notes = restoreWorld(world, c);
      const std::size_t skipped = schedule.skipBefore(world.time());
      std::string where;
      for (int m = 0; m < world.numMannequins(); ++m) {
        const skeleton::VectorX& q = world.q(m);
        where += fmt::format("{}{} at ({:.3f}, {:.3f}, {:.3f}){}", where.empty() ? "" : ", ", world.name(m), q(0), q(1), q(2),
                             world.calibrated(m) ? " calibrated" : " not calibrated");
      }
      const double age = static_cast<double>(transport::wallNs() - c.written_ns()) * 1e-9;
      spdlog::info("{}: resumed from {} (written {:.3f} s ago): step {}, t {:.3f} s, {}{}", config.name, config.resume, age,
                   world.stepCount(), world.time(), where,
                   world.numObjects() > 0 ? fmt::format(", {} object pose(s)", world.numObjects()) : std::string());
      for (const std::string& n : notes) spdlog::warn("{}: resumed: {}", config.name, n);
      if (skipped > 0) spdlog::warn("{}: resumed: {} timed trigger(s) before t {:.3f} s skipped", config.name, skipped, world.time());
    } catch (const std::exception& e) {  // std::runtime_error (file), std::invalid_argument (mismatch)
      spdlog::error("{}: checkpoint refused, starting fresh from the initial pose: {}", config.name, e.what());
    }
  }

  void checkpoint() {
    if (!checkpoint_writer) return;
    const std::int64_t now = transport::steadyNs();
    if (last_checkpoint_ns != 0 && now - last_checkpoint_ns < static_cast<std::int64_t>(config.checkpoint_period * 1e9)) return;
    last_checkpoint_ns = now;
    toCheckpoint(world, world_msg, transport::wallNs(), checkpoint_msg);
    checkpoint_writer->submit(encodeCheckpoint(checkpoint_msg));
    const std::uint64_t failed = checkpoint_writer->failed();
    if (failed > checkpoint_failures_logged) {
      checkpoint_failures_logged = failed;
      spdlog::warn("{}: checkpoint not written ({} failure(s)): {}", config.name, failed, checkpoint_writer->lastError());
    }
  }

  void onTrigger(const v1::Trigger& t) {
    const scenario::Engine& e = *world.scenarioEngine();
    if (e.scenario().triggerIndex(t.name()) < 0) {
      spdlog::warn("{}: trigger '{}' from {}: scenario '{}' does not declare it (ignored)", config.name, t.name(),
                   t.header().source(), e.scenario().name);
      return;
    }
    spdlog::info("{}: trigger '{}'{} from {}", config.name, t.name(), t.value().empty() ? "" : " = " + t.value(), t.header().source());
    world.trigger(t.name(), t.value());
  }

  void publishScenario() {
    const ScenarioWatch::Tick tick = watch.after(world);
    if (tick.engine == nullptr) return;
    const scenario::Engine& e = *tick.engine;
    if (tick.switched) {
      const std::string events = tick.first ? "" : ScenarioWatch::events(e);
      spdlog::info("{}: scenario '{}' at {:.3f} s: state '{}'{}", config.name, e.scenario().name, world.time(), e.stateName(),
                   events.empty() ? "" : " (" + events + ")");
    }
    if (!tick.publish) return;
    toScenarioState(e, world.time(), scenario_msg);
    pub.publish(topics::kScenarioState, scenario_msg);
  }

  static std::vector<std::string> subscriberEndpoints(const SimServiceConfig& c) {
    std::vector<std::string> out = c.connect;
    for (const MocapSourceEntry& e : c.mocap_sources)
      for (const std::string& ep : e.connect)
        if (std::find(out.begin(), out.end(), ep) == out.end()) out.push_back(ep);
    return out;
  }

  // The World source of a frame: the `mocap_sources` entry named like its publisher (Header.source),
  // else the default source "". nullptr when no mannequin uses that source (the frame is dropped).
  const std::string* sourceOf(const v1::MocapFrame& f) const {
    static const std::string kDefault;
    const std::string* name = &kDefault;
    for (const MocapSourceEntry& e : config.mocap_sources)
      if (e.name == f.header().source()) name = &e.name;
    for (const std::string& w : world_sources)
      if (w == *name) return name;
    return nullptr;
  }

  void onMocap(const v1::MocapFrame& f) {
    ++stats.mocap_frames;
    const std::string* src = sourceOf(f);
    if (src == nullptr) {
      ++unused_source_frames;
      return;
    }
    if (config.mode == Mode::kReplay) {
      pending.push_back(f);
      return;
    }
    const sim::StepDriver::Added added = driver.addFrame(transport::fromMsg(f), *src, config.reanchor_threshold);
    new_mocap = true;
    if (added.reanchored)
      spdlog::info("{}: capture clock{} {} by {:.3f} s: re-anchored", config.name, src->empty() ? "" : " of " + *src,
                   added.drift_s > 0 ? "ahead" : "behind", std::abs(added.drift_s));
  }

  // "contacts 6 (mean 5.8, max 8), max penetration 1.23 mm, balance operator 0.043 m (min 0.012 m)".
  std::string physicsLine(const sim::RunTotals& t, bool current) const {
    if (!world.physics()) return "physics off";
    const sim::StepDiagnostics& d = world.diagnostics();
    std::string line = current ? fmt::format("contacts {} (mean {:.1f}, max {})", d.contacts,
                                             t.steps > 0 ? t.contact_sum / static_cast<double>(t.steps) : 0.0, t.max_contacts)
                               : fmt::format("contacts mean {:.1f}, max {}",
                                             t.steps > 0 ? t.contact_sum / static_cast<double>(t.steps) : 0.0, t.max_contacts);
    line += fmt::format(", max penetration {:.2f} mm", t.max_penetration_m * 1e3);
    if (t.failed_collision_pairs > 0) line += fmt::format(", {} collision pair tests failed (no contact)", t.failed_collision_pairs);
    line += ", balance";
    const auto dist = [](double v) { return std::isfinite(v) ? fmt::format("{:.3f} m", v) : std::string("none"); };
    for (int m = 0; m < world.numMannequins(); ++m) {
      line += fmt::format("{} {} ", m > 0 ? "," : "", world.name(m));
      const double minb = t.min_balance_per_mannequin_m[static_cast<std::size_t>(m)];
      if (current)
        line += fmt::format("{} (min {})", dist(world.mannequinDiagnostics(m).balance_distance_m), dist(minb));
      else
        line += fmt::format("min {}", dist(minb));
    }
    return line;
  }

  void statusLine() {
    if (config.status_period <= 0) return;
    const std::int64_t now = transport::steadyNs();
    if (now - last_status_ns < static_cast<std::int64_t>(config.status_period * 1e9)) return;
    last_status_ns = now;
    spdlog::info("{}: t {:.3f} s, {} steps, {} sim.world, {} mocap frames | {}", config.name, world.time(), stats.steps,
                 stats.worlds, stats.mocap_frames, physicsLine(period, true));
    period.reset(world.numMannequins());
  }

  void onContacts(const v1::ContactSet& s) {
    ++stats.contact_sets;
    if (!awaiting || s.step() != awaited_step) return;  // an answer to an older query: ignored
    contacts = s;
    has_contacts = true;
    stale = false;
    awaiting = false;
  }

  // Waits for the contacts of the query in flight, up to the deadline; past it the previous set stays
  // in use and is flagged stale.
  void waitForContacts(const std::atomic<bool>& stop) {
    const double deadline = config.mode == Mode::kReplay ? config.collision.replay_deadline : config.collision.deadline;
    const std::int64_t until = query_sent_ns + static_cast<std::int64_t>(deadline * 1e9);
    while (awaiting && !stop.load()) {
      const std::int64_t left = until - transport::steadyNs();
      if (left <= 0) break;
      sub.poll(microseconds(std::min<std::int64_t>(left / 1000, 20000)));
    }
    if (awaiting) {
      stale = true;
      ++stats.stale_contacts;
      awaiting = false;
    }
  }

  // Before a step: collision lockstep. Live: pipelined, the answer to query n is awaited before query
  // n + period (the steps in between use whichever set arrived). Replay: synchronous, the answer is
  // awaited right after the query, so every step uses the contacts of the last query step — the same
  // set whatever the timing (deterministic output).
  void collisionBeforeStep(const std::atomic<bool>& stop) {
    if (config.collision.mode != CollisionMode::kService) return;
    if (world.stepCount() % static_cast<std::uint64_t>(config.collision.period_steps) != 0) return;
    if (awaiting) waitForContacts(stop);
    toCollisionQuery(world, config.collision.margin, query_msg);
    pub.publish(topics::kCollisionQuery, query_msg);
    ++stats.queries;
    awaiting = true;
    awaited_step = world.stepCount();
    query_sent_ns = transport::steadyNs();
    if (config.mode == Mode::kReplay) waitForContacts(stop);
  }

  // After each step: the scenario's state, the totals, sim.world at world_rate (or at each new mocap frame).
  void afterStep(bool ok) {
    publishScenario();
    ++stats.steps;
    period.add(world, ok);
    run_totals.add(world, ok);
    health.loopIteration();
    const bool scheduled = world_rate.tick();
    if (scheduled || (config.publish_on_mocap && new_mocap)) {
      toWorldState(world, has_contacts ? &contacts : nullptr, stale, config.mode == Mode::kReplay, world_msg);
      pub.publish(topics::kSimWorld, world_msg);
      ++stats.worlds;
      checkpoint();
      new_mocap = false;
    }
  }

  void updateHealth() {
    health.setStat("steps", static_cast<double>(stats.steps));
    health.setStat("sim_time_s", world.time());
    health.setStat("worlds", static_cast<double>(stats.worlds));
    health.setStat("mocap_frames", static_cast<double>(stats.mocap_frames));
    if (config.collision.mode == CollisionMode::kService) health.setStat("stale_contacts", static_cast<double>(stats.stale_contacts));
    health.setStat("overruns", static_cast<double>(stats.overruns));
    health.setStat("dropped_steps", static_cast<double>(stats.dropped_steps));
    double worst_pos = 0;
    int calibrated = 0;
    for (int i = 0; i < world.numMannequins(); ++i) {
      calibrated += world.calibrated(i);
      for (const auto& st : world.controlFrames(i)) worst_pos = std::max(worst_pos, st.position_error);
    }
    health.setStat("calibrated", calibrated);
    health.setStat("worst_position_error_m", worst_pos);
    if (world.failedSteps() > 0) health.setState(v1::SERVICE_STATE_DEGRADED, "numerical failure in a step");
  }
};

SimService::SimService(const SimServiceConfig& config, zmq::context_t& context, double heartbeat_period)
    : impl_(std::make_unique<Impl>(config, context, heartbeat_period)) {}

SimService::~SimService() = default;

SimStats SimService::stats() const { return impl_->stats; }
std::vector<std::string> SimService::boundEndpoints() const { return impl_->pub.boundEndpoints(); }

int SimService::run(const std::atomic<bool>& stop, double duration) {
  Impl& s = *impl_;
  spdlog::info("{}: {} mode, step {} ms, sim.world at {:.1f} Hz, {} mannequin(s) stepped by the {}, publishing on {}, connected to {}",
               s.config.name, s.config.mode == Mode::kLive ? "live" : "replay", s.config.world.step * 1e3,
               s.config.world_rate, s.world.numMannequins(),
               s.config.stepper == StepperKind::kController ? "controller" : "kinematic tracker", fmt::join(s.pub.boundEndpoints(), ", "),
               fmt::join(s.config.connect, ", "));
  if (!s.config.mocap_sources.empty()) {
    std::string list;
    for (const MocapSourceEntry& e : s.config.mocap_sources) {
      int users = 0;
      for (const MannequinEntry& m : s.config.mannequins) users += m.mocap_source == e.name;
      list += fmt::format("{}{} ({} mannequin(s){}{})", list.empty() ? "" : ", ", e.name, users, e.connect.empty() ? "" : ", ",
                          fmt::join(e.connect, ", "));
    }
    spdlog::info("{}: mocap sources (by the publisher's name): {}", s.config.name, list);
  }
  s.stop_flag = &stop;
  s.last_status_ns = transport::steadyNs();
  std::int64_t next = transport::steadyNs();
  service::ServiceLoop(s.health, stop, duration)
      .run(
          [&] {
            s.pub.poll();
            if (s.config.mode == Mode::kReplay) {
              s.sub.poll(milliseconds(20));
              while (!s.pending.empty() && !stop.load()) {
                const std::string& src = *s.sourceOf(s.pending.front());  // pending holds frames of used sources only
                const mocap::Frame in = transport::fromMsg(s.pending.front());
                s.pending.pop_front();
                s.driver.addFrame(in, src);
                s.new_mocap = true;
                s.driver.stepTo(in.stamp_ns, src);
              }
            } else {
              const std::int64_t now = transport::steadyNs();
              if (now < next) {
                s.sub.poll(microseconds((next - now) / 1000));
                if (transport::steadyNs() < next) return true;
              }
              const std::int64_t late = transport::steadyNs() - next;
              s.health.lateness(static_cast<double>(late) * 1e-9);
              s.sub.poll(microseconds(0));
              s.driver.stepOnce();
              next += s.step_ns;
              if (late > 10'000'000) {  // more than 10 ms behind: resynchronise instead of running a burst of steps
                ++s.stats.overruns;
                s.stats.dropped_steps += static_cast<std::uint64_t>(late / s.step_ns);
                next = transport::steadyNs() + s.step_ns;
              }
            }
            if (s.stats.steps % 64 == 0) s.updateHealth();
            s.statusLine();
            return true;
          },
          {}, [&] { s.updateHealth(); });
  spdlog::info("{}: stopped after {} steps ({:.3f} s simulated), {} mocap frames, {} sim.world | {}", s.config.name,
               s.stats.steps, s.world.time(), s.stats.mocap_frames, s.stats.worlds, s.physicsLine(s.run_totals, false));
  if (s.unused_source_frames > 0)
    spdlog::warn("{}: {} mocap frames of a source no mannequin uses were dropped", s.config.name, s.unused_source_frames);
  return 0;
}

}  // namespace mannequin::simservice
