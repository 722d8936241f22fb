// The `security` section every service reads (services/common): key files beside the config, errors
// naming FILE:LINE of the entry, and the options it gives a publisher and a subscriber.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "mannequin/service/runtime.hpp"
#include "mannequin/transport/security.hpp"
#include "test_util.hpp"

using namespace mannequin;
using namespace mannequin::transport;
using mannequin::transport::testing::TempDir;

namespace {

class SecurityConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
    std::filesystem::create_directories(dir.path() / "keys");
    for (const char* name : {"sim", "mocap", "render1"}) {
      const CurveKeyPair k = generateCurveKeyPair();
      writeKeyFile(key(std::string(name) + ".key_secret"), k.secret_key, "secret", 0600);
      writeKeyFile(key(std::string(name) + ".key"), k.public_key, "public", 0644);
      pairs[name] = k;
    }
  }
  std::string key(const std::string& file) const { return (dir.path() / "keys" / file).string(); }
  /// Writes the config and resolves it as a service would.
  service::Endpoints resolve(const std::string& yaml) {
    config_path = (dir.path() / "svc.yaml").string();
    std::ofstream(config_path) << yaml;
    service::CommonOptions o;
    o.config = config_path;
    return service::resolveEndpoints(o, service::loadConfig(o), "svc");
  }
  std::string error(const std::string& yaml) {
    try {
      resolve(yaml);
    } catch (const core::ConfigError& e) {
      return e.what();
    }
    return "no error";
  }
  TempDir dir;
  std::map<std::string, CurveKeyPair> pairs;
  std::string config_path;
};

const char* kGood =
    "publish: tcp://127.0.0.1:0\n"
    "connect: tcp://127.0.0.1:5999\n"
    "security:\n"
    "  secret_key_file: keys/sim.key_secret\n"
    "  public_key_file: keys/sim.key\n"
    "  server_public_key_file: keys/mocap.key\n"
    "  authorized_keys: [keys/render1.key, \"%s\"]\n";

std::string good(const std::string& inline_key) {
  std::string s = kGood;
  return s.replace(s.find("%s"), 2, inline_key);
}

}  // namespace

TEST_F(SecurityConfig, NoSectionIsPlaintextAsBefore) {
  const service::Endpoints e = resolve("publish: ipc:///tmp/x\n");
  EXPECT_FALSE(e.security.enabled());
  EXPECT_FALSE(service::publisherOptions(e).curve.has_value());
  EXPECT_FALSE(service::subscriberOptions(e).curve.has_value());
}

TEST_F(SecurityConfig, KeysAreReadBesideTheConfig) {
  const service::Endpoints e = resolve(good(pairs["mocap"].public_key));
  const PublisherOptions p = service::publisherOptions(e);
  ASSERT_TRUE(p.curve.has_value());
  EXPECT_EQ(p.curve->secret_key, pairs["sim"].secret_key);
  EXPECT_EQ(p.curve->authorized_keys, (std::vector<std::string>{pairs["render1"].public_key, pairs["mocap"].public_key}));
  const SubscriberOptions s = service::subscriberOptions(e);
  ASSERT_TRUE(s.curve.has_value());
  EXPECT_EQ(s.curve->public_key, pairs["sim"].public_key);
  EXPECT_EQ(s.curve->secret_key, pairs["sim"].secret_key);
  EXPECT_EQ(s.curve->server_public_key, pairs["mocap"].public_key);
}

// A path of 40 characters is also 40 characters of the Z85 alphabet ('/', '.', '-', letters, digits): an entry
// naming a file that exists is that key file, not a key written inline (CI found it: the launcher's run
// directory /tmp/mq-e2e-hosts-4169/keys/launch.a.key made a client's key file look like a key).
TEST_F(SecurityConfig, AnAuthorizedKeyFileWhosePathLooksLikeAZ85KeyIsReadAsAFile) {
  const std::string rel = "keys/a-path-of-forty-characters-long.key";
  ASSERT_EQ(rel.size(), 40u);
  ASSERT_TRUE(isZ85Key(rel));
  writeKeyFile((dir.path() / rel).string(), pairs["render1"].public_key, "public", 0644);
  const service::Endpoints e = resolve(
      "publish: tcp://127.0.0.1:0\nsecurity:\n  secret_key_file: keys/sim.key_secret\n  authorized_keys: [" + rel + "]\n");
  const PublisherOptions p = service::publisherOptions(e);
  ASSERT_TRUE(p.curve.has_value());
  EXPECT_EQ(p.curve->authorized_keys, (std::vector<std::string>{pairs["render1"].public_key}));
  // without the file, the same 40 characters are taken as a key written inline
  std::filesystem::remove(dir.path() / rel);
  EXPECT_EQ(service::publisherOptions(resolve("publish: tcp://127.0.0.1:0\nsecurity:\n  secret_key_file: keys/sim.key_secret\n"
                                              "  authorized_keys: [" + rel + "]\n")).curve->authorized_keys,
            (std::vector<std::string>{rel}));
}

TEST_F(SecurityConfig, BadEntriesNameFileAndLine) {
  const std::string ok = pairs["mocap"].public_key;
  std::string y = good(ok);
  // a missing secret file: line 4
  std::string bad = y;
  bad.replace(bad.find("keys/sim.key_secret"), 19, "keys/none.key_secret");
  std::string msg = error(bad);
  EXPECT_NE(msg.find(config_path + ":4: field 'security.secret_key_file'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("none.key_secret"), std::string::npos) << msg;
  // a world-readable secret
  ::chmod(key("sim.key_secret").c_str(), 0644);
  msg = error(y);
  EXPECT_NE(msg.find(config_path + ":4:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("readable by others"), std::string::npos) << msg;
  ::chmod(key("sim.key_secret").c_str(), 0600);
  // a public key file of another pair: line 5
  bad = y;
  bad.replace(bad.find("public_key_file: keys/sim.key"), 29, "public_key_file: keys/render1.key");
  msg = error(bad);
  EXPECT_NE(msg.find(config_path + ":5: field 'security.public_key_file'"), std::string::npos) << msg;
  // an authorized entry that is neither a key nor a key file: line 7
  msg = error(good("keys/nobody.key"));
  EXPECT_NE(msg.find(config_path + ":7:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nobody.key"), std::string::npos) << msg;
  // a server key file that is not a key
  std::ofstream(key("garbage.key")) << "hello\n";
  bad = y;
  bad.replace(bad.find("keys/mocap.key"), 14, "keys/garbage.key");
  msg = error(bad);
  EXPECT_NE(msg.find(config_path + ":6: field 'security.server_public_key_file'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not a Z85 CURVE key"), std::string::npos) << msg;
  // connecting without the server key; an unknown key
  msg = error("publish: ipc:///tmp/x\nconnect: ipc:///tmp/y\nsecurity:\n  secret_key_file: keys/sim.key_secret\n  authorized_keys: []\n");
  EXPECT_NE(msg.find("server_public_key_file"), std::string::npos) << msg;
  msg = error("publish: ipc:///tmp/x\nsecurity:\n  secret_key_file: keys/sim.key_secret\n  authorized_keys: []\n  secret: 1\n");
  EXPECT_NE(msg.find("secret"), std::string::npos) << msg;
  EXPECT_NE(msg.find(config_path + ":"), std::string::npos) << msg;
}

TEST_F(SecurityConfig, ConfiguredServicesTalkOverCurve) {
  // mocap admits sim; sim connects with mocap's public key (each from its own config)
  const service::Endpoints mocap = resolve(
      "name: mocap\npublish: tcp://127.0.0.1:0\nsecurity:\n  secret_key_file: keys/mocap.key_secret\n"
      "  authorized_keys: [keys/sim.key]\n");
  zmq::context_t ctx;
  Publisher pub(ctx, service::publisherOptions(mocap));
  const service::Endpoints sim = resolve("name: sim\npublish: tcp://127.0.0.1:0\nconnect: " + pub.boundEndpoints().at(0) +
                                         "\nsecurity:\n  secret_key_file: keys/sim.key_secret\n"
                                         "  server_public_key_file: keys/mocap.key\n  authorized_keys: []\n");
  Subscriber sub(ctx, service::subscriberOptions(sim));
  ASSERT_TRUE(mannequin::transport::testing::handshake(pub, sub, 10000)) << "no heartbeat over CURVE within 10 s";
  EXPECT_GE(pub.curveAdmissions(), 1u);
  EXPECT_EQ(pub.curveRefusals(), 0u);
}

TEST_F(SecurityConfig, ASecurityFileGivesOneServerKeyPerPublisherAndReplacesTheConfigs) {
  // what mannequin-launch writes: `servers` (each endpoint's key), passed with --security FILE
  const std::string file = (dir.path() / "sim.security.yaml").string();
  std::ofstream(file) << "security:\n  secret_key_file: keys/sim.key_secret\n  servers:\n"
                         "    - {connect: 'tcp://10.0.0.1:5601', public_key_file: keys/mocap.key}\n"
                         "    - {connect: 'tcp://10.0.0.2:5602', public_key_file: keys/render1.key}\n"
                         "  authorized_keys: [keys/mocap.key]\n";
  config_path = (dir.path() / "svc.yaml").string();
  std::ofstream(config_path) << "publish: tcp://127.0.0.1:0\nconnect: [tcp://10.0.0.1:5601, tcp://10.0.0.2:5602]\n";
  service::CommonOptions o;
  o.config = config_path;
  o.security = file;
  const service::Endpoints e = service::resolveEndpoints(o, service::loadConfig(o), "svc");
  const SubscriberOptions s = service::subscriberOptions(e);
  ASSERT_TRUE(s.curve.has_value());
  EXPECT_EQ(s.curve->server_public_key, "");
  EXPECT_EQ(s.curve->server_keys, (std::map<std::string, std::string>{{"tcp://10.0.0.1:5601", pairs["mocap"].public_key},
                                                                     {"tcp://10.0.0.2:5602", pairs["render1"].public_key}}));
  EXPECT_EQ(service::publisherOptions(e).curve->authorized_keys, (std::vector<std::string>{pairs["mocap"].public_key}));
  // errors name the security file's FILE:LINE
  std::ofstream(file) << "security:\n  secret_key_file: keys/sim.key_secret\n  servers:\n"
                         "    - {connect: 'tcp://10.0.0.1:5601', public_key_file: keys/none.key}\n  authorized_keys: []\n";
  try {
    service::resolveEndpoints(o, service::loadConfig(o), "svc");
    ADD_FAILURE() << "a missing server key file was accepted";
  } catch (const core::ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find(file + ":4: field 'security.servers[0].public_key_file'"), std::string::npos) << err.what();
  }
  std::ofstream(file) << "publish: x\n";
  try {
    service::resolveEndpoints(o, service::loadConfig(o), "svc");
    ADD_FAILURE() << "a security file with another key was accepted";
  } catch (const core::ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find(file + ":1: field 'publish': unknown key"), std::string::npos) << err.what();
  }
}
