// The collision service's query handler (mannequin::collisionservice): a query poses the mannequins
// and answers the contacts of the CollisionWorld with names split into mannequin and segment and witness
// points in world frames; a bad query gets an error and no contacts; a bad config names FILE:LINE.
#include <gtest/gtest.h>

#include <cmath>

#include "mannequin/collisionservice/collision_service.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/transport/convert.hpp"

using namespace mannequin;
using namespace mannequin::collisionservice;

namespace {

const char* kConfig = R"(name: collision
publish: ipc:///tmp/unused
scene: configs/scenes/floor.yaml
activation_distance: 0.02
mannequins:
  - {name: operator, config: configs/mannequins/male_50th.yaml, margin: 0.0, self_collision: false}
)";

CollisionServiceConfig config() { return parseCollisionConfig(core::ConfigNode::parse(kConfig, "collision.yaml")); }

v1::CollisionQuery standingQuery(const skeleton::Model& model, double lift = 0.0) {
  v1::CollisionQuery q;
  q.mutable_header()->set_stamp_ns(123456789);
  q.set_step(42);
  v1::MannequinConfiguration* m = q.add_mannequins();
  m->set_name("operator");
  skeleton::VectorX qs = skeleton::standingConfiguration(model);
  qs(2) += lift;  // root.pz
  for (int k = 0; k < model.nq; ++k) m->add_q(qs(k));
  return q;
}

TEST(CollisionQueryHandler, StandingFeetTouchTheFloorWithSplitNamesAndWorldPoints) {
  const CollisionServiceConfig c = config();
  ASSERT_EQ(c.mannequins.size(), 1u);
  QueryHandler handler(c);
  v1::ContactSet out;
  ASSERT_TRUE(handler.answer(standingQuery(c.mannequins[0].model), out)) << out.error();
  EXPECT_EQ(out.step(), 42u);
  EXPECT_EQ(out.header().stamp_ns(), 123456789);
  EXPECT_TRUE(out.error().empty());
  int feet = 0;
  for (const v1::Contact& k : out.contacts()) {
    // the floor is a scene body (no mannequin); the other side is one of the operator's segments
    const bool floor_a = k.mannequin_a().empty();
    const std::string& scene_body = floor_a ? k.body_a() : k.body_b();
    const std::string& mannequin = floor_a ? k.mannequin_b() : k.mannequin_a();
    const std::string& segment = floor_a ? k.body_b() : k.body_a();
    ASSERT_EQ(scene_body, "scene/floor");
    EXPECT_EQ(mannequin, "operator");
    EXPECT_EQ(segment.find('/'), std::string::npos) << segment;
    EXPECT_LE(k.distance(), 0.02 + 1e-12);
    const math::Vector3 on_floor = transport::fromMsg(floor_a ? k.point_a_world() : k.point_b_world());
    EXPECT_NEAR(on_floor.z(), 0.0, 1e-9);  // the floor's witness point is on the plane z = 0
    const math::Vector3 on_body = transport::fromMsg(floor_a ? k.point_b_world() : k.point_a_world());
    EXPECT_NEAR(on_body.z(), k.distance(), 1e-9);  // the body's witness point is `distance` above it
    feet += segment == "foot_l" || segment == "foot_r";
  }
  EXPECT_EQ(feet, 8);  // flat soles: four corners each
}

TEST(CollisionQueryHandler, LiftedOneMetreNothingTouches) {
  const CollisionServiceConfig c = config();
  QueryHandler handler(c);
  v1::ContactSet out;
  ASSERT_TRUE(handler.answer(standingQuery(c.mannequins[0].model, 1.0), out)) << out.error();
  EXPECT_EQ(out.contacts_size(), 0);
}

TEST(CollisionQueryHandler, BadQueriesGetAnErrorAndNoContacts) {
  const CollisionServiceConfig c = config();
  const skeleton::Model& model = c.mannequins[0].model;
  QueryHandler handler(c);
  v1::ContactSet out;
  auto expectError = [&](const v1::CollisionQuery& q, const std::string& what) {
    EXPECT_FALSE(handler.answer(q, out));
    EXPECT_NE(out.error().find(what), std::string::npos) << out.error();
    EXPECT_EQ(out.contacts_size(), 0);
    EXPECT_EQ(out.step(), q.step());
  };
  v1::CollisionQuery unknown = standingQuery(model);
  unknown.mutable_mannequins(0)->set_name("ghost");
  expectError(unknown, "unknown mannequin 'ghost'");
  v1::CollisionQuery short_q = standingQuery(model);
  short_q.mutable_mannequins(0)->mutable_q()->RemoveLast();
  expectError(short_q, "coordinates, expected " + std::to_string(model.nq));
  v1::CollisionQuery nan = standingQuery(model);
  nan.mutable_mannequins(0)->set_q(5, NAN);
  expectError(nan, "non-finite configuration");
  v1::CollisionQuery body = standingQuery(model);
  body.add_bodies()->set_body("scene/floor");  // static: cannot be moved
  expectError(body, "no movable body 'scene/floor'");
  // after bad queries a good one is answered as before
  EXPECT_TRUE(handler.answer(standingQuery(model), out));
  EXPECT_GT(out.contacts_size(), 0);
}

TEST(CollisionServiceConfig, ErrorsNameTheFileLineAndField) {
  auto error = [](const std::string& text) -> std::string {
    try {
      parseCollisionConfig(core::ConfigNode::parse(text, "c.yaml"));
    } catch (const core::ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error("publish: x\nmannequins: []\nsceen: a.yaml\n").find("sceen"), std::string::npos);
  const std::string missing = error("mannequins:\n  - {name: a, config: configs/mannequins/nobody.yaml}\n");
  EXPECT_NE(missing.find("c.yaml:2"), std::string::npos) << missing;
  EXPECT_NE(missing.find("nobody.yaml"), std::string::npos) << missing;
  const std::string twice = error(
      "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml}\n"
      "  - {name: a, config: configs/mannequins/male_50th.yaml}\n");
  EXPECT_NE(twice.find("two mannequins named 'a'"), std::string::npos) << twice;
  EXPECT_NE(error("mannequins: []\nactivation_distance: -1\n").find("activation_distance"), std::string::npos);
}

}  // namespace
