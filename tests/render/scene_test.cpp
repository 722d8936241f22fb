// The scene model: what buildScene draws from a WorldState (no GL).
#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "mannequin/collision/scene.hpp"
#include "mannequin/math/frame.hpp"
#include "mannequin/render/scene.hpp"

namespace mannequin::render {
namespace {

using testing::addContact;
using testing::addMannequin;

const Primitive* findTag(const RenderScene& s, const std::string& tag, Kind kind) {
  for (const Primitive& p : s.solids)
    if (p.tag == tag && p.kind == kind) return &p;
  return nullptr;
}

TEST(RenderScene, OneCapsulePerSegmentAtTheSegmentPoseInTheMannequinsColour) {
  const skeleton::Model model = testing::male50();
  const math::VectorX q = skeleton::standingConfiguration(model);
  v1::WorldState ws;
  ws.set_step(42);
  addMannequin(ws, model, q, "alice");
  SceneAssets assets;
  assets.addModel(model.name, model);  // found by model name
  const Style style;
  const RenderScene scene = buildScene(ws, assets, style);
  EXPECT_EQ(scene.step, 42u);
  ASSERT_EQ(scene.count(Layer::kMannequin), model.segments.size());

  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, q);
  for (const skeleton::Segment& seg : model.segments) {
    const Primitive* p = nullptr;
    for (const Primitive& s : scene.solids)
      if (s.tag == "mannequin:alice/" + seg.name) p = &s;
    ASSERT_NE(p, nullptr) << seg.name;
    EXPECT_EQ(p->colour, style.mannequin_colours[0]);
    const SE3& oMi = d.oMi[static_cast<std::size_t>(seg.joint)];
    const Vector3 a = oMi.act(seg.capsule.a), b = oMi.act(seg.capsule.b);
    EXPECT_DOUBLE_EQ(p->radius, seg.capsule.radius);
    if (p->kind == Kind::kCapsule) {
      // the capsule's axis ends are the model's capsule ends in the world
      const Vector3 e0 = p->pose.p - 0.5 * p->length * p->pose.R.col(2);
      const Vector3 e1 = p->pose.p + 0.5 * p->length * p->pose.R.col(2);
      const double err = std::min((e0 - a).norm() + (e1 - b).norm(), (e0 - b).norm() + (e1 - a).norm());
      EXPECT_LT(err, 1e-9) << seg.name;
      EXPECT_LT((p->pose.R.transpose() * p->pose.R - math::Matrix3::Identity()).norm(), 1e-12);
    } else {
      ASSERT_EQ(p->kind, Kind::kSphere) << seg.name;
      EXPECT_LT((p->pose.p - a).norm(), 1e-9);
    }
  }
  // a standing mannequin: its lowest capsule reaches the floor, its highest is above 1.5 m
  double lo = 1e9, hi = -1e9;
  for (const Primitive& p : scene.solids) {
    const double h = p.kind == Kind::kCapsule ? 0.5 * p.length * std::abs(p.pose.R(2, 2)) : 0.0;
    lo = std::min(lo, p.pose.p.z() - h - p.radius);
    hi = std::max(hi, p.pose.p.z() + h + p.radius);
  }
  EXPECT_LT(std::abs(lo), 0.03);
  EXPECT_GT(hi, 1.5);
}

TEST(RenderScene, EachMannequinHasItsOwnColourAndAnUnknownModelIsDrawnAsSpheres) {
  const skeleton::Model model = testing::male50();
  v1::WorldState ws;
  addMannequin(ws, model, skeleton::standingConfiguration(model), "alice");
  addMannequin(ws, model, skeleton::standingConfiguration(model), "bob")->set_model("unknown_model");
  SceneAssets assets;
  assets.addModel("alice", model);  // found by mannequin name; bob's model is unknown
  const RenderScene scene = buildScene(ws, assets);
  const Primitive* a = nullptr;
  const Primitive* b = nullptr;
  for (const Primitive& p : scene.solids) {
    if (p.tag.rfind("mannequin:alice/", 0) == 0) a = &p;
    if (p.tag.rfind("mannequin:bob/", 0) == 0) {
      b = &p;
      EXPECT_EQ(p.kind, Kind::kSphere) << p.tag;
    }
  }
  ASSERT_TRUE(a && b);
  EXPECT_NE(a->colour, b->colour);
  EXPECT_EQ(scene.countTagged("mannequin:bob/"), model.segments.size());
}

TEST(RenderScene, AContactForceBecomesAnArrowWhoseLengthAndColourFollowTheNorm) {
  const skeleton::Model model = testing::male50();
  v1::WorldState ws;
  v1::MannequinState* ms = addMannequin(ws, model, skeleton::standingConfiguration(model), "alice");
  const Vector3 p(0.5, 0.2, 0.75);
  addContact(*ms, p, Vector3::UnitZ(), Vector3(0, 0, 100), "alice/hand_l", "table");    // 100 N up
  addContact(*ms, p + Vector3(0, 0.1, 0), Vector3::UnitZ(), Vector3::Zero(), "alice/hand_r", "table");  // no force
  Style style;
  const RenderScene scene = buildScene(ws, SceneAssets{}, style);
  EXPECT_EQ(scene.count(Layer::kContact), 2u);
  EXPECT_EQ(scene.countTagged("force:alice/hand_r"), 0u);  // no force, no arrow
  const Primitive* cone = findTag(scene, "force:alice/hand_l:table", Kind::kCone);
  const Primitive* shaft = findTag(scene, "force:alice/hand_l:table", Kind::kCylinder);
  ASSERT_TRUE(cone && shaft);
  const double len = style.force_scale * 100.0;  // 0.2 m, inside [min, max]
  const Vector3 tip = cone->pose.p + cone->length * cone->pose.R.col(2);
  EXPECT_LT((tip - (p + Vector3(0, 0, len))).norm(), 1e-12);
  EXPECT_LT((shaft->pose.p - 0.5 * shaft->length * shaft->pose.R.col(2) - p).norm(), 1e-12);  // starts at the point
  EXPECT_EQ(cone->colour, forceColour(100.0, style));

  // colour: yellow at 0 N to red at force_full; green falls monotonically with the norm
  const Colour c0 = forceColour(0, style), c1 = forceColour(0.5 * style.force_full, style),
               c2 = forceColour(style.force_full, style), c3 = forceColour(10 * style.force_full, style);
  EXPECT_GT(c0[1], c1[1]);
  EXPECT_GT(c1[1], c2[1]);
  EXPECT_EQ(c2, c3);
  EXPECT_GT(c2[0], 0.9f);
  EXPECT_LT(c2[1], 0.15f);

  // the force on the mannequin is drawn: a physics contact has the floor as body_a, its force (on a) points down
  v1::WorldState fl;
  v1::MannequinState* fm = fl.add_mannequins();
  fm->set_name("op");
  addContact(*fm, p, Vector3::UnitZ(), Vector3(0, 0, -100), "scene/floor", "op/foot_l");
  const RenderScene sf = buildScene(fl, SceneAssets{}, style);
  const Primitive* up = findTag(sf, "force:scene/floor:op/foot_l", Kind::kCone);
  ASSERT_NE(up, nullptr);
  EXPECT_GT(up->pose.R.col(2).z(), 1.0 - 1e-12);  // pointing up, out of the floor

  // length is clamped: a huge force is force_max_length long
  v1::WorldState big;
  addContact(*big.add_mannequins(), p, Vector3::UnitZ(), Vector3(1e6, 0, 0), "a", "b");
  const RenderScene sb = buildScene(big, SceneAssets{}, style);
  const Primitive* bc = findTag(sb, "force:a:b", Kind::kCone);
  ASSERT_NE(bc, nullptr);
  EXPECT_NEAR((bc->pose.p + bc->length * bc->pose.R.col(2) - p).norm(), style.force_max_length, 1e-12);
}

TEST(RenderScene, StaticSceneFromTheSceneFileAndObjectsAtTheirStatePose) {
  SceneAssets assets;
  assets.scene = collision::loadScene(testing::sourcePath("configs/scenes/table.yaml"));
  std::size_t shapes = 0, movable_shapes = 0;
  for (const auto& b : assets.scene.bodies) {
    shapes += b.shapes.size();
    if (b.movable) movable_shapes += b.shapes.size();
  }
  const RenderScene still = buildStaticScene(assets);
  EXPECT_EQ(still.solids.size(), shapes);
  EXPECT_EQ(still.count(Layer::kObject), movable_shapes);
  const Primitive* floor = findTag(still, "scene:floor", Kind::kPlane);
  ASSERT_NE(floor, nullptr);
  EXPECT_LT((floor->normal - Vector3::UnitZ()).norm(), 1e-12);
  EXPECT_LT(floor->pose.p.norm(), 1e-12);
  const Primitive* top = findTag(still, "scene:table", Kind::kBox);
  ASSERT_NE(top, nullptr);
  EXPECT_LT((top->pose.p - Vector3(0.8, 0, 0.73)).norm(), 1e-12);  // body pose · shape pose

  v1::WorldState ws;
  v1::ObjectState* ball = ws.add_objects();
  ball->set_name("ball");
  testing::toMsg(SE3(math::Matrix3::Identity(), Vector3(0.3, -0.4, 0.11)), *ball->mutable_pose());
  const RenderScene moved = buildScene(ws, assets);
  const Primitive* b = findTag(moved, "object:ball", Kind::kSphere);
  ASSERT_NE(b, nullptr);
  EXPECT_LT((b->pose.p - Vector3(0.3, -0.4, 0.11)).norm(), 1e-12);
  // an object without a state stays at its scene pose
  const Primitive* tool = findTag(moved, "object:tool", Kind::kBox);
  ASSERT_NE(tool, nullptr);
  EXPECT_LT((tool->pose.p - Vector3(0.7, -0.2, 0.77)).norm(), 1e-12);
}

TEST(RenderScene, SupportPolygonIsTheHullOfTheFeetContactsOnTheFloor) {
  v1::WorldState ws;
  v1::MannequinState* ms = ws.add_mannequins();
  ms->set_name("alice");
  testing::toMsg(Vector3(0.05, 0.0, 0.95), *ms->mutable_com());
  const std::vector<Vector3> feet{{0.2, 0.15, 0.0}, {-0.05, 0.15, 0.0}, {-0.05, -0.15, 0.0}, {0.2, -0.15, 0.0},
                                  {0.05, 0.1, 0.0}};  // the last inside
  for (const Vector3& f : feet) addContact(*ms, f, Vector3::UnitZ(), Vector3(0, 0, 150), "alice/foot", "floor");
  addContact(*ms, Vector3(0.6, 0, 0.75), Vector3::UnitZ(), Vector3(0, 0, 50), "alice/hand_l", "table");  // not support
  addContact(*ms, Vector3(0.6, 0.3, 0.0), Vector3::UnitZ(), Vector3::Zero(), "alice/toe", "floor");     // not pressing
  const RenderScene scene = buildScene(ws, SceneAssets{});
  ASSERT_EQ(scene.lines.size(), 1u);
  const Polyline& l = scene.lines[0];
  EXPECT_TRUE(l.closed);
  ASSERT_EQ(l.points.size(), 4u);
  for (const Vector3& p : l.points) {
    bool corner = false;
    for (int i = 0; i < 4; ++i) corner |= (p.head<2>() - feet[static_cast<std::size_t>(i)].head<2>()).norm() < 1e-12;
    EXPECT_TRUE(corner) << p.transpose();
  }
  EXPECT_EQ(scene.countTagged("com:alice"), 1u);
}

TEST(RenderScene, AControlFrameDrawsItsPoseAndTargetAxesAndAnErrorLineOnlyWhenTheyDiffer) {
  v1::WorldState ws;
  v1::MannequinState* ms = ws.add_mannequins();
  ms->set_name("alice");
  const SE3 actual(math::frameAlong(Vector3(0, 1, 0)), Vector3(0.3, 0.1, 1.0));
  const SE3 target(math::Matrix3::Identity(), Vector3(0.3, 0.4, 1.1));
  testing::addControlFrame(*ms, "hand_r", actual, target);
  const Style style;
  const RenderScene scene = buildScene(ws, SceneAssets{}, style);
  EXPECT_EQ(scene.count(Layer::kControl), 3u);  // the achieved pose's three axes
  EXPECT_EQ(scene.countTagged("control:alice/hand_r"), 3u);
  for (const Primitive& p : scene.solids) {
    if (p.layer != Layer::kControl) continue;
    // each axis cylinder starts at the frame's origin and runs along one of its axes
    const Vector3 start = p.pose.p - 0.5 * p.length * p.pose.R.col(2);
    EXPECT_LT((start - actual.p).norm(), 1e-12);
    EXPECT_NEAR(p.length, style.control_axis_length, 1e-12);
    double best = 0;
    for (int a = 0; a < 3; ++a) best = std::max(best, p.pose.R.col(2).dot(actual.R.col(a)));
    EXPECT_NEAR(best, 1.0, 1e-12);
  }
  int target_axes = 0, error_lines = 0;
  for (const Polyline& l : scene.lines) {
    ASSERT_EQ(l.layer, Layer::kControl);
    ASSERT_EQ(l.points.size(), 2u);
    if (l.colour == style.control_error_colour) {
      ++error_lines;
      EXPECT_LT((l.points[0] - actual.p).norm(), 1e-12);
      EXPECT_LT((l.points[1] - target.p).norm(), 1e-12);
    } else {
      ++target_axes;
      EXPECT_LT((l.points[0] - target.p).norm(), 1e-12);
      EXPECT_NEAR((l.points[1] - l.points[0]).norm(), style.control_axis_length, 1e-12);
    }
  }
  EXPECT_EQ(target_axes, 3);
  EXPECT_EQ(error_lines, 1);
  // the target on the pose: axes, no error line
  ms->mutable_control_frames(0)->mutable_target()->CopyFrom(ms->control_frames(0).actual());
  const RenderScene same = buildScene(ws, SceneAssets{}, style);
  EXPECT_EQ(same.lines.size(), 3u);
  for (const Polyline& l : same.lines) EXPECT_NE(l.colour, style.control_error_colour);
  // an occluded frame (tracked false): its target drawn grey
  ms->mutable_control_frames(0)->set_tracked(false);
  for (const Polyline& l : buildScene(ws, SceneAssets{}, style).lines) EXPECT_EQ(l.colour, style.control_untracked_colour);
  // without an achieved pose (or target) nothing is drawn for it but the other
  ms->mutable_control_frames(0)->clear_actual();
  const RenderScene no_actual = buildScene(ws, SceneAssets{}, style);
  EXPECT_EQ(no_actual.count(Layer::kControl), 0u);
  EXPECT_EQ(no_actual.lines.size(), 3u);
}

TEST(RenderScene, ConvexHullIsCounterClockwiseWithoutInteriorOrCollinearPoints) {
  const auto h = convexHull({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}, {0, 1}});
  ASSERT_EQ(h.size(), 4u);
  double area2 = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const auto& a = h[i];
    const auto& b = h[(i + 1) % h.size()];
    area2 += a[0] * b[1] - a[1] * b[0];
  }
  EXPECT_DOUBLE_EQ(area2, 8.0);  // +2 · area: counter-clockwise
  EXPECT_EQ(convexHull({{1, 1}}).size(), 1u);
}

}  // namespace
}  // namespace mannequin::render
