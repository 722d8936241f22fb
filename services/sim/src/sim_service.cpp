#include "mannequin/simservice/sim_service.hpp"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <deque>

#include "mannequin/service/runtime.hpp"
#include "mannequin/simservice/messages.hpp"
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
  bool new_mocap = false;
  std::int64_t step_ns;
  double world_phase = 0.0;  // fraction of a sim.world period accumulated (exact average rate)
  // collision lockstep
  v1::ContactSet contacts;
  bool has_contacts = false;
  bool stale = false;
  bool awaiting = false;
  std::uint64_t awaited_step = 0;
  std::int64_t query_sent_ns = 0;
  v1::WorldState world_msg;
  v1::CollisionQuery query_msg;

  Impl(const SimServiceConfig& c, zmq::context_t& ctx, double hb)
      : config(c),
        world(buildMannequins(c), c.world),
        pub(ctx, transport::PublisherOptions{c.name, c.publish, 1000, c.mode == Mode::kReplay}),
        sub(ctx, transport::SubscriberOptions{c.name, c.connect, c.mode == Mode::kReplay ? 100000 : 1000, 10000}),
        health(pub, c.name, &sub, hb) {
    step_ns = static_cast<std::int64_t>(std::llround(c.world.step * 1e9));
    sub.subscribe(topics::kMocapFrame, std::function<void(const v1::MocapFrame&)>([this](const v1::MocapFrame& f) { onMocap(f); }),
                  transport::validateMocapFrame);
    sub.subscribe(topics::kCollisionContacts,
                  std::function<void(const v1::ContactSet&)>([this](const v1::ContactSet& s) { onContacts(s); }),
                  transport::validateContactSet);
  }

  void onMocap(const v1::MocapFrame& f) {
    ++stats.mocap_frames;
    if (config.mode == Mode::kReplay) {
      pending.push_back(f);
      return;
    }
    const mocap::Frame in = transport::fromMsg(f);
    world.addMocap(in);
    new_mocap = true;
    if (!world.anchored()) {
      world.anchor(in.stamp_ns);
    } else {
      const double drift = static_cast<double>(in.stamp_ns - world.captureTimeNs()) * 1e-9 - config.world.interpolation_delay;
      if (std::abs(drift) > config.reanchor_threshold) {
        spdlog::info("{}: capture clock {} by {:.3f} s: re-anchored", config.name, drift > 0 ? "ahead" : "behind", std::abs(drift));
        world.anchor(in.stamp_ns);
      }
    }
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

  void stepOnce(const std::atomic<bool>& stop) {
    collisionBeforeStep(stop);
    world.step();
    ++stats.steps;
    health.loopIteration();
    world_phase += config.world_rate * config.world.step;
    const bool scheduled = world_phase >= 1.0 - 1e-9;
    if (scheduled) world_phase -= 1.0;
    if (scheduled || (config.publish_on_mocap && new_mocap)) {
      toWorldState(world, has_contacts ? &contacts : nullptr, stale, config.mode == Mode::kReplay, world_msg);
      pub.publish(topics::kSimWorld, world_msg);
      ++stats.worlds;
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
  std::int64_t next = transport::steadyNs();
  service::ServiceLoop(s.health, stop, duration)
      .run(
          [&] {
            s.pub.poll();
            if (s.config.mode == Mode::kReplay) {
              s.sub.poll(milliseconds(20));
              while (!s.pending.empty() && !stop.load()) {
                const mocap::Frame in = transport::fromMsg(s.pending.front());
                s.pending.pop_front();
                s.world.addMocap(in);
                s.new_mocap = true;
                if (!s.world.anchored()) s.world.anchor(in.stamp_ns);
                while (s.world.captureTimeNs() + s.step_ns <= in.stamp_ns && !stop.load()) s.stepOnce(stop);
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
              s.stepOnce(stop);
              next += s.step_ns;
              if (late > 10'000'000) {  // more than 10 ms behind: resynchronise instead of running a burst of steps
                ++s.stats.overruns;
                next = transport::steadyNs() + s.step_ns;
              }
            }
            if (s.stats.steps % 64 == 0) s.updateHealth();
            return true;
          },
          {}, [&] { s.updateHealth(); });
  spdlog::info("{}: stopped after {} steps ({:.3f} s simulated), {} mocap frames, {} sim.world", s.config.name, s.stats.steps,
               s.world.time(), s.stats.mocap_frames, s.stats.worlds);
  return 0;
}

}  // namespace mannequin::simservice
