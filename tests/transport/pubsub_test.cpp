// Typed publish/subscribe over ipc and tcp loopback: headers, order, latest-value delivery,
// late joiners, sequence gaps, slow subscribers.
#include <gtest/gtest.h>

#include <set>
#include <thread>

#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/health.hpp"
#include "test_util.hpp"

using namespace mannequin;
using namespace mannequin::transport;
using mannequin::transport::testing::handshake;
using mannequin::transport::testing::TempDir;

namespace {
template <class M>
std::function<void(const M&)> collect(std::vector<M>& out) {
  return [&out](const M& m) { out.push_back(m); };
}
}  // namespace

TEST(PubSub, IpcRoundTripFillsTheHeaderAndKeepsOrder) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"mocap", {dir.ipc("mocap")}});
  Subscriber sub(ctx, {"sim", {dir.ipc("mocap")}});
  std::vector<v1::MocapFrame> got;
  sub.subscribe(topics::kMocapFrame, collect(got));
  ASSERT_TRUE(handshake(pub, sub));
  const std::int64_t before = wallNs();
  for (int i = 0; i < 100; ++i) {
    v1::MocapFrame f;
    f.mutable_header()->set_stamp_ns(1000 * i);
    f.set_frame_number(i);
    auto* b = f.add_bodies();
    b->set_name("pelvis");
    b->set_tracked(true);
    b->mutable_pose()->mutable_orientation()->set_w(1.0);
    pub.publish(topics::kMocapFrame, f);
  }
  for (int k = 0; k < 200 && got.size() < 100; ++k) sub.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(got.size(), 100u);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(got[i].frame_number(), static_cast<unsigned>(i));
    EXPECT_EQ(got[i].header().sequence(), static_cast<unsigned>(i + 1));
    EXPECT_EQ(got[i].header().stamp_ns(), 1000 * i);  // capture time untouched
    EXPECT_EQ(got[i].header().schema_version(), kSchemaVersion);
    EXPECT_EQ(got[i].header().source(), "mocap");
    EXPECT_GE(got[i].header().send_time_ns(), before);
  }
  const TopicCounters c = sub.counters("mocap.frame");
  EXPECT_EQ(c.received, 100u);
  EXPECT_EQ(c.delivered, 100u);
  EXPECT_EQ(c.dropped, 0u);
  EXPECT_EQ(c.malformed, 0u);
}

TEST(PubSub, TcpEphemeralPortIsResolved) {
  zmq::context_t ctx;
  Publisher pub(ctx, {"sim", {"tcp://127.0.0.1:0"}});
  ASSERT_EQ(pub.boundEndpoints().size(), 1u);
  const std::string ep = pub.boundEndpoints()[0];
  EXPECT_EQ(ep.rfind("tcp://127.0.0.1:", 0), 0u);
  EXPECT_NE(ep, "tcp://127.0.0.1:0");
  Subscriber sub(ctx, {"render", {ep}});
  std::vector<v1::WorldState> got;
  sub.subscribe(topics::kSimWorld, collect(got));
  ASSERT_TRUE(handshake(pub, sub));
  v1::WorldState w;
  w.set_step(7);
  w.add_mannequins()->add_q(0.25);
  pub.publish(topics::kSimWorld, w);
  for (int k = 0; k < 200 && got.empty(); ++k) sub.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].step(), 7u);
  EXPECT_EQ(got[0].mannequins(0).q(0), 0.25);
}

TEST(PubSub, DeterministicModeWritesNoSendTime) {
  TempDir dir;
  zmq::context_t ctx;
  PublisherOptions o{"sim", {dir.ipc("sim")}};
  o.deterministic = true;
  Publisher pub(ctx, o);
  v1::Header h;
  pub.fillHeader("sim.world", h);
  EXPECT_EQ(h.send_time_ns(), 0);
  EXPECT_EQ(h.sequence(), 1u);
  pub.fillHeader("sim.world", h);
  EXPECT_EQ(h.sequence(), 2u);
  pub.fillHeader("mocap.frame", h);
  EXPECT_EQ(h.sequence(), 1u);  // sequences are per topic
}

TEST(PubSub, LatestOnlyDeliversTheNewestStateOfABacklog) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"sim", {dir.ipc("sim")}});
  Subscriber sub(ctx, {"render", {dir.ipc("sim")}});
  std::vector<v1::WorldState> got;
  sub.subscribe(topics::kSimWorld, collect(got));
  ASSERT_TRUE(handshake(pub, sub));
  // Bursts of 50 states, drained by polls until all 50 are received: whatever part of the burst a
  // poll drains, it delivers only its newest state and counts the others superseded, and the last
  // state delivered is the newest of the burst. Bursts are repeated until one poll drained a backlog
  // (more than one state): how the burst is split over polls is up to the sockets' timing.
  std::uint64_t step = 0;
  bool backlog = false;
  for (int burst = 0; burst < 20 && !backlog; ++burst) {
    const TopicCounters start = sub.counters("sim.world");
    for (int i = 0; i < 50; ++i) {
      v1::WorldState w;
      w.set_step(++step);
      pub.publish(topics::kSimWorld, w);
    }
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (sub.counters("sim.world").received - start.received < 50) {
      ASSERT_LT(std::chrono::steady_clock::now(), until)
          << "burst " << burst << ": " << sub.counters("sim.world").received - start.received << " of 50 states received in 10 s";
      const TopicCounters before = sub.counters("sim.world");
      const std::size_t delivered_before = got.size();
      sub.poll(std::chrono::milliseconds(2));
      const TopicCounters after = sub.counters("sim.world");
      const std::uint64_t drained = after.received - before.received;
      ASSERT_EQ(got.size() - delivered_before, drained > 0 ? 1u : 0u) << "one state per poll, of " << drained << " drained";
      EXPECT_EQ(after.superseded - before.superseded, drained > 0 ? drained - 1 : 0u);
      EXPECT_EQ(after.delivered - before.delivered, drained > 0 ? 1u : 0u);
      if (drained > 0) {
        EXPECT_EQ(got.back().step(), step - 50 + (after.received - start.received)) << "the newest drained";
      }
      backlog = backlog || drained > 1;
    }
    ASSERT_FALSE(got.empty());
    EXPECT_EQ(got.back().step(), step);
  }
  EXPECT_TRUE(backlog) << "no poll drained more than one state in 20 bursts of 50";
  const TopicCounters c = sub.counters("sim.world");
  EXPECT_EQ(c.received, step);
  EXPECT_EQ(c.delivered + c.superseded, step);
  EXPECT_EQ(c.delivered, got.size());
  EXPECT_EQ(c.dropped, 0u);
}

TEST(PubSub, LateJoinerGetsTheCurrentStateAtOnceAndOthersIgnoreTheRepeat) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"scenario", {dir.ipc("scenario")}});
  Subscriber early(ctx, {"early", {dir.ipc("scenario")}});
  std::vector<v1::ScenarioState> early_got;
  early.subscribe(topics::kScenarioState, collect(early_got));
  ASSERT_TRUE(handshake(pub, early));
  v1::ScenarioState s;
  s.set_state("assembly");
  pub.publish(topics::kScenarioState, s);
  for (int k = 0; k < 200 && early_got.empty(); ++k) early.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(early_got.size(), 1u);

  // published once, before the late subscriber existed
  Subscriber late(ctx, {"late", {dir.ipc("scenario")}});
  std::vector<v1::ScenarioState> late_got;
  late.subscribe(topics::kScenarioState, collect(late_got));
  for (int k = 0; k < 1000 && late_got.empty(); ++k) {
    pub.poll();
    late.poll(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(late_got.size(), 1u);
  EXPECT_EQ(late_got[0].state(), "assembly");
  EXPECT_EQ(late_got[0].header().sequence(), 1u);
  // the early subscriber saw the resend as a duplicate, not as a new state
  for (int k = 0; k < 10; ++k) early.poll(std::chrono::milliseconds(2));
  EXPECT_EQ(early_got.size(), 1u);
  EXPECT_GE(early.counters("scenario.state").duplicates, 1u);
  bool resent = false;
  for (const auto& c : pub.counters())
    if (c.topic == "scenario.state") resent = c.resent >= 1;
  EXPECT_TRUE(resent);
}

TEST(PubSub, SequenceGapsAreCountedAsDroppedAndARestartIsAccepted) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"relay", {dir.ipc("relay")}});
  Subscriber sub(ctx, {"sim", {dir.ipc("relay")}});
  std::vector<v1::MocapFrame> got;
  sub.subscribe(topics::kMocapFrame, collect(got));
  ASSERT_TRUE(handshake(pub, sub));
  for (std::uint64_t seq : {1, 2, 5, 6, 1}) {  // 3 and 4 lost; then the source restarted
    v1::MocapFrame f;
    f.mutable_header()->set_schema_version(kSchemaVersion);
    f.mutable_header()->set_source("mocap");
    f.mutable_header()->set_sequence(seq);
    pub.publishRaw("mocap.frame", f.SerializeAsString());
  }
  for (int k = 0; k < 200 && got.size() < 5; ++k) sub.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(got.size(), 5u);
  EXPECT_EQ(sub.counters("mocap.frame").dropped, 2u);
}

TEST(PubSub, SlowSubscriberNeverStallsThePublisher) {
  TempDir dir;
  zmq::context_t ctx;
  PublisherOptions po{"sim", {dir.ipc("sim")}};
  po.send_hwm = 10;
  Publisher pub(ctx, po);
  SubscriberOptions so{"slow", {dir.ipc("sim")}};
  so.receive_hwm = 10;
  Subscriber sub(ctx, so);
  std::vector<v1::WorldState> got;
  sub.subscribe(topics::kSimWorld, collect(got));
  ASSERT_TRUE(handshake(pub, sub));
  // 20 000 states of ~2 KB while the subscriber does not read: publish() must return every time
  v1::WorldState w;
  for (int i = 0; i < 250; ++i) w.add_mannequins()->add_q(i);
  for (int i = 1; i <= 20000; ++i) {
    w.set_step(i);
    pub.publish(topics::kSimWorld, w);
  }
  // then it reads: only what the queues held
  for (int k = 0; k < 20; ++k) sub.poll(std::chrono::milliseconds(2));
  ASSERT_FALSE(got.empty());
  EXPECT_LT(sub.counters("sim.world").received, 20000u);
  // and the newest state still arrives once the subscriber keeps up
  w.set_step(20001);
  pub.publish(topics::kSimWorld, w);
  for (int k = 0; k < 200 && got.back().step() != 20001u; ++k) sub.poll(std::chrono::milliseconds(5));
  EXPECT_EQ(got.back().step(), 20001u);
  EXPECT_GT(sub.counters("sim.world").dropped, 0u);  // lost in the full queues, seen as a sequence gap
}

TEST(PubSub, HeartbeatCarriesServiceCountersAndStats) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"mocap", {dir.ipc("mocap")}});
  Subscriber sub(ctx, {"launcher", {dir.ipc("mocap")}});
  std::vector<v1::Heartbeat> got;
  sub.subscribe(topics::kHeartbeat, collect(got));
  HealthReporter health(pub, "mocap", nullptr, 0.5);
  health.setState(v1::SERVICE_STATE_RUNNING);
  health.setStat("frames", 3);
  v1::MocapFrame f;
  for (int i = 0; i < 3; ++i) pub.publish(topics::kMocapFrame, f);
  health.loopIteration(3);
  health.lateness(0.002);
  ASSERT_TRUE(health.tick(true));
  EXPECT_FALSE(health.tick());  // period not elapsed
  for (int k = 0; k < 1000 && got.empty(); ++k) {
    pub.poll();
    sub.poll(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(got.size(), 1u);
  const v1::Heartbeat& hb = got[0];
  EXPECT_EQ(hb.service(), "mocap");
  EXPECT_EQ(hb.pid(), getpid());
  EXPECT_EQ(hb.state(), v1::SERVICE_STATE_RUNNING);
  EXPECT_NEAR(hb.worst_lateness_ms(), 2.0, 1e-9);
  ASSERT_EQ(hb.topics_size(), 1);
  EXPECT_EQ(hb.topics(0).topic(), "mocap.frame");
  EXPECT_TRUE(hb.topics(0).published());
  EXPECT_EQ(hb.topics(0).messages(), 3u);
  ASSERT_EQ(hb.stats_size(), 1);
  EXPECT_EQ(hb.stats(0).name(), "frames");
  EXPECT_EQ(hb.stats(0).value(), 3.0);
}

TEST(PubSub, LatestOnlyKeepsTheNewestOfEachSource) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher a(ctx, {"sim_a", {dir.ipc("a")}});
  Publisher b(ctx, {"sim_b", {dir.ipc("b")}});
  Subscriber sub(ctx, {"render", {dir.ipc("a"), dir.ipc("b")}});
  std::vector<v1::WorldState> got;
  sub.subscribe(topics::kSimWorld, collect(got));
  ASSERT_TRUE(handshake(a, sub));
  ASSERT_TRUE(handshake(b, sub));
  // Bursts of 5 states from each source, drained by polls until all 10 are received: a poll delivers
  // at most one state per source, its newest (a newer state of one source never hides the other's);
  // the last delivered of each source is its newest. Repeated until one poll delivered both sources
  // after superseding (how a burst is split over polls is up to the sockets' timing).
  std::uint64_t step = 0;
  bool both = false;
  for (int burst = 0; burst < 20 && !both; ++burst) {
    const TopicCounters start = sub.counters("sim.world");
    for (int i = 0; i < 5; ++i) {
      v1::WorldState w;
      w.set_step(++step);
      a.publish(topics::kSimWorld, w);
      w.set_step(1000 + step);
      b.publish(topics::kSimWorld, w);
    }
    std::uint64_t last_a = 0, last_b = 0;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (sub.counters("sim.world").received - start.received < 10) {
      ASSERT_LT(std::chrono::steady_clock::now(), until)
          << "burst " << burst << ": " << sub.counters("sim.world").received - start.received << " of 10 states received in 10 s";
      const TopicCounters before = sub.counters("sim.world");
      const std::size_t first = got.size();
      sub.poll(std::chrono::milliseconds(2));
      const TopicCounters after = sub.counters("sim.world");
      int from_a = 0, from_b = 0;
      for (std::size_t k = first; k < got.size(); ++k) {
        const bool is_a = got[k].header().source() == "sim_a";
        (is_a ? from_a : from_b) += 1;
        (is_a ? last_a : last_b) = got[k].step();
      }
      EXPECT_LE(from_a, 1);
      EXPECT_LE(from_b, 1);
      const std::uint64_t drained = after.received - before.received;
      EXPECT_EQ(after.superseded - before.superseded + (got.size() - first), drained);
      both = both || (from_a == 1 && from_b == 1 && after.superseded > before.superseded);
    }
    EXPECT_EQ(last_a, step);
    EXPECT_EQ(last_b, 1000 + step);
  }
  EXPECT_TRUE(both) << "no poll delivered both sources after superseding in 20 bursts";
  const TopicCounters c = sub.counters("sim.world");
  EXPECT_EQ(c.received, 2 * step);
  EXPECT_EQ(c.delivered + c.superseded, 2 * step);
}

// Publisher::subscribed: a publisher sees which topics its subscribers asked for (mannequin-trigger waits for
// the sim's scenario.trigger subscription before it sends); a negative linger is refused.
TEST(PubSub, ThePublisherSeesWhichTopicsAreSubscribed) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"trigger", {dir.ipc("trigger")}});
  EXPECT_FALSE(pub.subscribed("scenario.trigger"));
  Subscriber sub(ctx, {"sim", {dir.ipc("trigger")}});
  std::vector<v1::Trigger> got;
  sub.subscribe(topics::kScenarioTrigger, collect(got));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!pub.subscribed("scenario.trigger") && std::chrono::steady_clock::now() < deadline) {
    pub.poll();
    sub.poll(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(pub.subscribed("scenario.trigger")) << "no subscription within 5 s";
  EXPECT_FALSE(pub.subscribed("sim.world"));  // only what was asked for
  // once subscribed, a message sent is received
  v1::Trigger t;
  t.set_name("go");
  pub.publish(topics::kScenarioTrigger, t);
  for (int k = 0; k < 1000 && got.empty(); ++k) sub.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(got.size(), 1u);
  PublisherOptions bad{"x", {dir.ipc("bad")}};
  bad.linger_ms = -1;
  EXPECT_THROW(Publisher(ctx, bad), std::invalid_argument);
}
