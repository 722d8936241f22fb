// ZeroMQ CURVE on the cluster's pub/sub over tcp loopback: a listed client receives; an unlisted key,
// a wrong server key and a plaintext client get nothing (an unlisted key is logged and counted); an
// unlisted publisher cannot feed a CURVE subscriber of mocap frames. "Nothing" is asserted over 1 s of
// publishing after the listed client did receive.
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <memory>

#include "mannequin/transport/security.hpp"
#include "test_util.hpp"

using namespace mannequin;
using namespace mannequin::transport;
using mannequin::transport::testing::TempDir;
using Clock = std::chrono::steady_clock;

namespace {

constexpr auto kDeadline = std::chrono::seconds(10);       // for what must happen
constexpr auto kQuietPeriod = std::chrono::milliseconds(1000);  // for what must not

PublisherOptions curvePublisher(const std::string& source, const CurveKeyPair& server, std::vector<std::string> listed) {
  PublisherOptions o;
  o.source = source;
  o.endpoints = {"tcp://127.0.0.1:0"};
  o.curve = CurveServerOptions{server.secret_key, std::move(listed)};
  return o;
}

SubscriberOptions curveSubscriber(const std::string& name, const std::string& endpoint, const CurveKeyPair& client,
                                  const std::string& server_public) {
  SubscriberOptions o;
  o.name = name;
  o.endpoints = {endpoint};
  o.curve = CurveClientOptions{client.public_key, client.secret_key, server_public};
  return o;
}

/// Counts the mocap frames a subscriber gets, per source.
struct Counter {
  explicit Counter(Subscriber& s) : sub(s) {
    sub.subscribe(topics::kMocapFrame, std::function<void(const v1::MocapFrame&)>([this](const v1::MocapFrame& f) {
                    ++got;
                    if (f.header().source() != "mocap") ++foreign;
                  }));
  }
  Subscriber& sub;
  int got = 0;
  int foreign = 0;  // frames from any source but "mocap"
};

void publishFrame(Publisher& pub, int i) {
  v1::MocapFrame f;
  f.set_frame_number(static_cast<unsigned>(i));
  auto* b = f.add_bodies();
  b->set_name("pelvis");
  b->set_tracked(true);
  b->mutable_pose()->mutable_orientation()->set_w(1.0);
  pub.publish(topics::kMocapFrame, f);
}

/// Publishes a frame every ~2 ms on every publisher and polls every counter until `done()` or the
/// deadline; returns done().
template <class Done>
bool pump(const std::vector<Publisher*>& pubs, const std::vector<Counter*>& subs, Clock::duration deadline, Done done) {
  static int frame = 0;
  const auto until = Clock::now() + deadline;
  while (!done() && Clock::now() < until) {
    ++frame;
    for (Publisher* p : pubs) publishFrame(*p, frame);
    for (Counter* c : subs) c->sub.poll(std::chrono::milliseconds(1));
  }
  return done();
}

/// Captures spdlog output (the ZAP handler logs refusals from its thread).
class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(256)), previous_(spdlog::default_logger()) {
    auto logger = std::make_shared<spdlog::logger>("capture", sink_);
    logger->set_level(spdlog::level::debug);
    spdlog::set_default_logger(logger);
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  std::string text() const {
    std::string all;
    for (const std::string& line : sink_->last_formatted()) all += line;
    return all;
  }

 private:
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
  std::shared_ptr<spdlog::logger> previous_;
};

class Curve : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
    server = generateCurveKeyPair();
    listed = generateCurveKeyPair();
    other = generateCurveKeyPair();
  }
  /// The publisher admitting `listed` only, and a listed subscriber to it.
  void start() {
    pub = std::make_unique<Publisher>(ctx, curvePublisher("mocap", server, {listed.public_key}));
    endpoint = pub->boundEndpoints().at(0);
    good_sub = std::make_unique<Subscriber>(ctx, curveSubscriber("listed", endpoint, listed, server.public_key));
    good = std::make_unique<Counter>(*good_sub);
  }
  /// Runs until the listed client got 20 frames (fails loudly at the deadline), then 1 s more.
  void runThenQuiet(Counter& intruder) {
    ASSERT_TRUE(pump({pub.get()}, {good.get(), &intruder}, kDeadline, [&] { return good->got >= 20; }))
        << "the listed client got " << good->got << " frames within " << kDeadline.count() << " s";
    const int before = good->got;
    pump({pub.get()}, {good.get(), &intruder}, kQuietPeriod, [] { return false; });
    EXPECT_GT(good->got, before) << "the listed client kept receiving during the quiet period";
  }

  zmq::context_t ctx;
  CurveKeyPair server, listed, other;
  std::unique_ptr<Publisher> pub;
  std::string endpoint;
  std::unique_ptr<Subscriber> good_sub;
  std::unique_ptr<Counter> good;
};

}  // namespace

TEST_F(Curve, ListedClientReceivesOverTcp) {
  start();
  ASSERT_TRUE(pump({pub.get()}, {good.get()}, kDeadline, [&] { return good->got >= 20; })) << good->got;
  EXPECT_EQ(good->foreign, 0);
  EXPECT_GE(pub->curveAdmissions(), 1u);
  EXPECT_EQ(pub->curveRefusals(), 0u);
  EXPECT_EQ(good_sub->counters("mocap.frame").malformed, 0u);
}

TEST_F(Curve, UnlistedClientGetsNothingAndIsLoggedAndCounted) {
  LogCapture log;
  start();
  Subscriber intruder_sub(ctx, curveSubscriber("unlisted", endpoint, other, server.public_key));
  Counter intruder(intruder_sub);
  runThenQuiet(intruder);
  EXPECT_EQ(intruder.got, 0);
  EXPECT_EQ(intruder_sub.counters("mocap.frame").received, 0u);
  ASSERT_TRUE(pump({pub.get()}, {}, kDeadline, [&] { return pub->curveRefusals() >= 1; }))
      << "no refusal counted within the deadline";
  const std::string text = log.text();
  EXPECT_NE(text.find("refused CURVE client key " + other.public_key), std::string::npos) << text;
  EXPECT_NE(text.find("127.0.0.1"), std::string::npos) << text;  // the peer address
  EXPECT_EQ(text.find("refused CURVE client key " + listed.public_key), std::string::npos) << "the listed key was refused: " << text;
  EXPECT_NE(text.find("admitted CURVE client " + listed.public_key), std::string::npos) << text;
}

TEST_F(Curve, ClientWithAWrongServerKeyGetsNothing) {
  start();
  // its own key is listed, but it expects another server: the handshake never completes
  Subscriber wrong_sub(ctx, curveSubscriber("wrong-server", endpoint, listed, other.public_key));
  Counter wrong(wrong_sub);
  runThenQuiet(wrong);
  EXPECT_EQ(wrong.got, 0);
  EXPECT_EQ(wrong_sub.counters("mocap.frame").received, 0u);
}

TEST_F(Curve, PlaintextClientToACurveEndpointGetsNothing) {
  start();
  Subscriber plain_sub(ctx, SubscriberOptions{"plaintext", {endpoint}});
  Counter plain(plain_sub);
  runThenQuiet(plain);
  EXPECT_EQ(plain.got, 0);
  EXPECT_EQ(plain_sub.counters("mocap.frame").received, 0u);
}

TEST_F(Curve, UnlistedPublisherCannotFeedACurveSubscriberOfMocapFrames) {
  start();
  // intruders where the subscriber also connects: a CURVE publisher with its own keys (admitting the
  // subscriber's key) and a plaintext one, both publishing mocap frames under another source
  const CurveKeyPair rogue_keys = generateCurveKeyPair();
  Publisher rogue(ctx, curvePublisher("intruder", rogue_keys, {listed.public_key}));
  Publisher plain(ctx, PublisherOptions{"intruder-plain", {"tcp://127.0.0.1:0"}});
  good_sub->connect(rogue.boundEndpoints().at(0));
  good_sub->connect(plain.boundEndpoints().at(0));
  ASSERT_TRUE(pump({pub.get(), &rogue, &plain}, {good.get()}, kDeadline, [&] { return good->got >= 20; })) << good->got;
  pump({pub.get(), &rogue, &plain}, {good.get()}, kQuietPeriod, [] { return false; });
  EXPECT_EQ(good->foreign, 0) << "frames from an unlisted publisher reached the subscriber";
  EXPECT_EQ(rogue.curveAdmissions(), 0u);  // the subscriber never completed a handshake with it
}

TEST_F(Curve, PlaintextSocketsOfTheSameContextAreUnaffected) {
  start();  // the context now has a ZAP handler
  TempDir dir;
  Publisher plain_tcp(ctx, PublisherOptions{"mocap", {"tcp://127.0.0.1:0"}});
  Publisher plain_ipc(ctx, PublisherOptions{"mocap", {dir.ipc("plain")}});
  Subscriber tcp_sub(ctx, SubscriberOptions{"tcp", {plain_tcp.boundEndpoints().at(0)}});
  Subscriber ipc_sub(ctx, SubscriberOptions{"ipc", {dir.ipc("plain")}});
  Counter tcp(tcp_sub), ipc(ipc_sub);
  ASSERT_TRUE(pump({pub.get(), &plain_tcp, &plain_ipc}, {good.get(), &tcp, &ipc}, kDeadline,
                   [&] { return good->got >= 20 && tcp.got >= 20 && ipc.got >= 20; }))
      << "CURVE " << good->got << ", plaintext tcp " << tcp.got << ", ipc " << ipc.got;
  EXPECT_EQ(pub->curveRefusals(), 0u);
}

TEST_F(Curve, BadKeysAreRefusedAtConstruction) {
  EXPECT_THROW(Publisher(ctx, curvePublisher("p", CurveKeyPair{"x", "short"}, {})), std::invalid_argument);
  EXPECT_THROW(Publisher(ctx, curvePublisher("p", server, {"not-a-key"})), std::invalid_argument);
  EXPECT_THROW(Subscriber(ctx, curveSubscriber("s", "tcp://127.0.0.1:1", listed, "bad")), std::invalid_argument);
}

TEST(CurveKeys, PublicKeyOfTheSecretMatchesThePair) {
  if (!hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
  const CurveKeyPair k = generateCurveKeyPair();
  EXPECT_TRUE(isZ85Key(k.public_key));
  EXPECT_TRUE(isZ85Key(k.secret_key));
  EXPECT_EQ(curvePublicKey(k.secret_key), k.public_key);
  EXPECT_FALSE(isZ85Key(k.public_key.substr(1)));
  EXPECT_FALSE(isZ85Key(std::string(40, '"')));  // not in the Z85 alphabet
  EXPECT_THROW(curvePublicKey("nope"), std::invalid_argument);
}

TEST(CurveKeys, KeyFilesAreReadAndCheckedWithTheirName) {
  if (!hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
  TempDir dir;
  const CurveKeyPair k = generateCurveKeyPair();
  const std::string sec = (dir.path() / "a.key_secret").string(), pub = (dir.path() / "a.key").string();
  writeKeyFile(sec, k.secret_key, "secret", 0600);
  writeKeyFile(pub, k.public_key, "public", 0644);
  EXPECT_EQ(readKeyFile(sec, true), k.secret_key);
  EXPECT_EQ(readKeyFile(pub, false), k.public_key);
  EXPECT_THROW(writeKeyFile(sec, k.secret_key, "again", 0600), std::runtime_error);  // no overwrite
  EXPECT_EQ(readKeyFile(sec, true), k.secret_key);

  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ::chmod(sec.c_str(), 0644);
  EXPECT_NE(message([&] { readKeyFile(sec, true); }).find(sec + ": secret key file is readable by others"), std::string::npos);
  const std::string bad = (dir.path() / "bad.key").string();
  std::ofstream(bad) << "# comment\n\nnot-a-key\n";
  EXPECT_NE(message([&] { readKeyFile(bad, false); }).find(bad + ":3: not a Z85 CURVE key"), std::string::npos);
  const std::string missing = (dir.path() / "missing.key").string();
  EXPECT_NE(message([&] { readKeyFile(missing, false); }).find(missing + ": cannot read key file"), std::string::npos);
  const std::string empty = (dir.path() / "empty.key").string();
  std::ofstream(empty) << "# only a comment\n";
  EXPECT_NE(message([&] { readKeyFile(empty, false); }).find(empty + ": no key"), std::string::npos);
}

TEST_F(Curve, OneSubscriberHearsPublishersOfDifferentKeysEachByItsEndpointsKey) {
  // a deployment's services each have their own key pair: the sim connects to mocap and collision
  start();
  const CurveKeyPair second = generateCurveKeyPair();
  Publisher pub2(ctx, curvePublisher("collision", second, {listed.public_key}));
  SubscriberOptions o;
  o.name = "sim";
  o.curve = CurveClientOptions{listed.public_key, listed.secret_key, "", {{endpoint, server.public_key}}};
  o.curve->server_keys[pub2.boundEndpoints().at(0)] = second.public_key;
  o.endpoints = {endpoint, pub2.boundEndpoints().at(0)};
  Subscriber both_sub(ctx, o);
  int from_mocap = 0, from_collision = 0;
  both_sub.subscribe(topics::kMocapFrame, std::function<void(const v1::MocapFrame&)>([&](const v1::MocapFrame& f) {
                       from_mocap += f.header().source() == "mocap";
                       from_collision += f.header().source() == "collision";
                     }));
  const auto until = Clock::now() + kDeadline;
  for (int i = 1; (from_mocap < 10 || from_collision < 10) && Clock::now() < until; ++i) {
    publishFrame(*pub, i);
    publishFrame(pub2, i);
    both_sub.poll(std::chrono::milliseconds(2));
  }
  EXPECT_GE(from_mocap, 10);
  EXPECT_GE(from_collision, 10);
  // an endpoint with no key (no default either) is refused at connect, naming it
  try {
    both_sub.connect("tcp://127.0.0.1:5998");
    ADD_FAILURE() << "connected without a server key";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no server public key for 'tcp://127.0.0.1:5998'"), std::string::npos) << e.what();
  }
}
