// Malformed input on every topic: random bytes, bad framing, unknown topics, missing headers, wrong
// schema versions, NaN poses. All counted, none reaches a handler, good messages still flow.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "mannequin/transport/validate.hpp"
#include "test_util.hpp"

using namespace mannequin;
using namespace mannequin::transport;
using mannequin::transport::testing::handshake;
using mannequin::transport::testing::TempDir;

namespace {
struct Counts {
  int calls = 0;
};

// Subscribes to every topic of the table with a handler that counts calls.
void subscribeAll(Subscriber& sub, Counts& counts) {
  auto h = [&counts](const auto&) { ++counts.calls; };
  sub.subscribe(topics::kMocapFrame, std::function<void(const v1::MocapFrame&)>(h), validateMocapFrame);
  sub.subscribe(topics::kSimWorld, std::function<void(const v1::WorldState&)>(h));
  sub.subscribe(topics::kCollisionQuery, std::function<void(const v1::CollisionQuery&)>(h), validateCollisionQuery);
  sub.subscribe(topics::kCollisionContacts, std::function<void(const v1::ContactSet&)>(h), validateContactSet);
  sub.subscribe(topics::kScenarioCommand, std::function<void(const v1::ModeCommand&)>(h));
  sub.subscribe(topics::kScenarioState, std::function<void(const v1::ScenarioState&)>(h));
  sub.subscribe(topics::kScenarioTrigger, std::function<void(const v1::Trigger&)>(h));
  sub.subscribe(topics::kRenderSync, std::function<void(const v1::RenderSync&)>(h));
}

v1::MocapFrame goodFrame(std::uint64_t seq) {
  v1::MocapFrame f;
  f.mutable_header()->set_schema_version(kSchemaVersion);
  f.mutable_header()->set_source("mocap");
  f.mutable_header()->set_sequence(seq);
  auto* b = f.add_bodies();
  b->set_name("head");
  b->set_tracked(true);
  b->mutable_pose()->mutable_orientation()->set_w(1);
  return f;
}
}  // namespace

TEST(Malformed, RandomBytesOnEveryTopicAreCountedNeverDelivered) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"fuzzer", {dir.ipc("p")}});
  Subscriber sub(ctx, {"victim", {dir.ipc("p")}});
  Counts counts;
  subscribeAll(sub, counts);
  ASSERT_TRUE(handshake(pub, sub));
  std::mt19937 rng(7);
  int sent = 0;
  for (const auto& t : topics::kAll) {
    if (t.name == topics::kHeartbeat.name) continue;
    for (int i = 0; i < 50; ++i) {
      std::string bytes(1 + rng() % 300, '\0');
      for (char& c : bytes) c = static_cast<char>(rng());
      pub.publishRaw(t.name, bytes);
      ++sent;
    }
  }
  std::uint64_t received = 0;
  for (int k = 0; k < 500 && received < static_cast<std::uint64_t>(sent); ++k) {
    sub.poll(std::chrono::milliseconds(2));
    received = 0;
    for (const auto& c : sub.counters())
      if (c.topic != "health.heartbeat") received += c.received;
  }
  EXPECT_EQ(received, static_cast<std::uint64_t>(sent));
  // random bytes can happen to parse (protobuf is permissive) but never with a valid v1 header
  EXPECT_EQ(counts.calls, 0);
  for (const auto& c : sub.counters())
    if (c.topic != "health.heartbeat") {
      EXPECT_EQ(c.malformed, c.received) << c.topic;
    }
  // the subscriber still works
  auto f = goodFrame(1);
  pub.publishRaw("mocap.frame", f.SerializeAsString());
  for (int k = 0; k < 200 && counts.calls == 0; ++k) sub.poll(std::chrono::milliseconds(5));
  EXPECT_EQ(counts.calls, 1);
}

TEST(Malformed, BadHeadersSchemaVersionsAndNaNPoses) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"fuzzer", {dir.ipc("p")}});
  Subscriber sub(ctx, {"victim", {dir.ipc("p")}});
  Counts counts;
  subscribeAll(sub, counts);
  ASSERT_TRUE(handshake(pub, sub));

  v1::MocapFrame no_header;
  no_header.add_bodies()->set_name("x");
  auto wrong_version = goodFrame(1);
  wrong_version.mutable_header()->set_schema_version(2);
  auto no_source = goodFrame(2);
  no_source.mutable_header()->clear_source();
  auto seq0 = goodFrame(0);
  auto nan_pose = goodFrame(3);
  nan_pose.mutable_bodies(0)->mutable_pose()->mutable_position()->set_x(std::nan(""));
  auto bad_quat = goodFrame(4);
  bad_quat.mutable_bodies(0)->mutable_pose()->mutable_orientation()->set_w(0.2);
  auto unnamed = goodFrame(5);
  unnamed.mutable_bodies(0)->clear_name();
  auto occluded_nan = goodFrame(6);  // untracked bodies may carry garbage: accepted
  occluded_nan.mutable_bodies(0)->set_tracked(false);
  occluded_nan.mutable_bodies(0)->mutable_pose()->mutable_position()->set_x(std::nan(""));
  v1::ContactSet nan_contact;
  nan_contact.mutable_header()->set_schema_version(kSchemaVersion);
  nan_contact.mutable_header()->set_source("collision");
  nan_contact.mutable_header()->set_sequence(1);
  nan_contact.add_contacts()->set_distance(INFINITY);

  for (const auto* m : {&no_header, &wrong_version, &no_source, &seq0, &nan_pose, &bad_quat, &unnamed, &occluded_nan})
    pub.publishRaw("mocap.frame", m->SerializeAsString());
  pub.publishRaw("collision.contacts", nan_contact.SerializeAsString());
  // a truncated good message
  const std::string good = goodFrame(7).SerializeAsString();
  pub.publishRaw("mocap.frame", good.substr(0, good.size() - 3));
  pub.publishRaw("mocap.frame.v2", good);  // prefix-matches the subscription, not a known topic

  for (int k = 0; k < 500 && (sub.counters("mocap.frame").received < 9 || sub.unknownTopics() < 1); ++k)
    sub.poll(std::chrono::milliseconds(2));
  EXPECT_EQ(sub.counters("mocap.frame").received, 9u);
  EXPECT_EQ(sub.counters("mocap.frame").malformed, 8u);
  EXPECT_EQ(counts.calls, 1);  // only the occluded frame
  for (int k = 0; k < 100 && sub.counters("collision.contacts").received < 1; ++k) sub.poll(std::chrono::milliseconds(2));
  EXPECT_EQ(sub.counters("collision.contacts").malformed, 1u);
  EXPECT_EQ(sub.unknownTopics(), 1u);
}

TEST(Malformed, WrongFramingIsCounted) {
  TempDir dir;
  zmq::context_t ctx;
  zmq::socket_t raw(ctx, zmq::socket_type::pub);
  raw.bind(dir.ipc("raw"));
  Subscriber sub(ctx, {"victim", {dir.ipc("raw")}});
  std::vector<std::uint64_t> seen;  // header sequence of every delivered mocap.frame
  sub.subscribe(topics::kMocapFrame,
                std::function<void(const v1::MocapFrame&)>([&seen](const v1::MocapFrame& f) { seen.push_back(f.header().sequence()); }),
                validateMocapFrame);
  auto sendFrame = [&raw](std::uint64_t seq) {
    (void)raw.send(zmq::buffer(std::string("mocap.frame")), zmq::send_flags::sndmore);
    (void)raw.send(zmq::buffer(goodFrame(seq).SerializeAsString()), zmq::send_flags::none);
  };
  auto waitFor = [&](std::uint64_t seq) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::find(seen.begin(), seen.end(), seq) == seen.end()) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      sub.poll(std::chrono::milliseconds(5));
    }
    return true;
  };
  // the raw socket has no late-joiner resend: probe (sequences 1..999) until the subscription is in place
  bool joined = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  for (std::uint64_t k = 1; k < 1000 && !joined && std::chrono::steady_clock::now() < deadline; ++k) {
    sendFrame(k);
    sub.poll(std::chrono::milliseconds(2));
    joined = !seen.empty();
  }
  ASSERT_TRUE(joined) << "no probe frame reached the subscriber within 20 s";
  // bad framing: one part only, then three parts whose payload is a valid frame (sequence 500000)
  const std::string framed = goodFrame(500000).SerializeAsString();
  (void)raw.send(zmq::buffer(std::string("mocap.frame")), zmq::send_flags::none);
  (void)raw.send(zmq::buffer(std::string("mocap.frame")), zmq::send_flags::sndmore);
  (void)raw.send(zmq::buffer(framed), zmq::send_flags::sndmore);
  (void)raw.send(zmq::buffer(framed), zmq::send_flags::none);
  // a good frame after them: once it is delivered, both bad messages have been read (one socket, in order)
  sendFrame(1000000);
  ASSERT_TRUE(waitFor(1000000)) << "the good frame sent after the bad framing was not delivered within 20 s";
  EXPECT_EQ(sub.badFraming(), 2u);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 500000u), 0) << "the three-part message reached the handler";
}

TEST(Malformed, AThrowingHandlerIsCaughtAndCounted) {
  TempDir dir;
  zmq::context_t ctx;
  Publisher pub(ctx, {"mocap", {dir.ipc("p")}});
  Subscriber sub(ctx, {"victim", {dir.ipc("p")}});
  sub.subscribe(topics::kMocapFrame,
                std::function<void(const v1::MocapFrame&)>([](const v1::MocapFrame&) { throw std::runtime_error("boom"); }));
  ASSERT_TRUE(handshake(pub, sub));
  v1::MocapFrame f;
  pub.publish(topics::kMocapFrame, f);
  for (int k = 0; k < 200 && sub.handlerErrors() == 0; ++k) EXPECT_NO_THROW(sub.poll(std::chrono::milliseconds(5)));
  EXPECT_EQ(sub.handlerErrors(), 1u);
}
