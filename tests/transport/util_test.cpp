// Endpoints, conversions, the rate-limited log.
#include <gtest/gtest.h>

#include <cmath>

#include "mannequin/math/so3.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/log_limiter.hpp"
#include "mannequin/transport/publisher.hpp"

using namespace mannequin;
using namespace mannequin::transport;

TEST(Endpoint, Normalize) {
  EXPECT_EQ(normalizeEndpoint("tcp://127.0.0.1:0"), "tcp://127.0.0.1:*");
  EXPECT_EQ(normalizeEndpoint("tcp://127.0.0.1:5555"), "tcp://127.0.0.1:5555");
  EXPECT_EQ(normalizeEndpoint("ipc:///tmp/x"), "ipc:///tmp/x");
  EXPECT_THROW(normalizeEndpoint("udp://1.2.3.4:5"), std::invalid_argument);
  EXPECT_THROW(normalizeEndpoint("tcp://host"), std::invalid_argument);
  EXPECT_THROW(normalizeEndpoint("tcp://host:port"), std::invalid_argument);
  EXPECT_THROW(normalizeEndpoint("tcp://host:70000"), std::invalid_argument);
  EXPECT_THROW(normalizeEndpoint("ipc://"), std::invalid_argument);
}

TEST(Endpoint, BindFailureNamesTheEndpoint) {
  zmq::context_t ctx;
  try {
    Publisher pub(ctx, {"x", {"ipc:///nonexistent-dir-mannequin/sock"}});
    FAIL() << "expected a bind failure";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir-mannequin/sock"), std::string::npos) << e.what();
  }
}

TEST(Convert, PoseRoundTrip) {
  math::SE3 H;
  H.R = math::expSO3(math::Vector3(0.3, -1.2, 2.0));
  H.p = math::Vector3(1, -2, 0.5);
  v1::Pose msg;
  toMsg(H, msg);
  EXPECT_EQ(checkPose(msg), "");
  const math::SE3 back = fromMsg(msg);
  EXPECT_LT((back.R - H.R).norm(), 1e-12);
  EXPECT_LT((back.p - H.p).norm(), 1e-15);
  // a scaled quaternion is normalised on the way in, but flagged by checkPose
  msg.mutable_orientation()->set_w(msg.orientation().w() * 2);
  msg.mutable_orientation()->set_x(msg.orientation().x() * 2);
  msg.mutable_orientation()->set_y(msg.orientation().y() * 2);
  msg.mutable_orientation()->set_z(msg.orientation().z() * 2);
  EXPECT_LT((fromMsg(msg).R - H.R).norm(), 1e-12);
  EXPECT_NE(checkPose(msg).find("quaternion norm 2"), std::string::npos) << checkPose(msg);
  msg.mutable_position()->set_y(NAN);
  EXPECT_EQ(checkPose(msg), "position is not finite");
}

TEST(LogLimiter, OneLinePerKeyPerPeriod) {
  LogLimiter log(3600.0);
  EXPECT_TRUE(log.warn("a", "first a"));
  EXPECT_FALSE(log.warn("a", "second a"));
  EXPECT_FALSE(log.warn("a", "third a"));
  EXPECT_TRUE(log.warn("b", "first b"));
  EXPECT_EQ(log.suppressed(), 2u);
  LogLimiter fast(0.0);
  EXPECT_TRUE(fast.warn("a", "x"));
  EXPECT_TRUE(fast.warn("a", "x"));
}
