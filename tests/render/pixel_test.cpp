// Pixel tests on headless frames (EGL surfaceless, Mesa llvmpipe when there is no GPU).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <tuple>

#include "fixtures.hpp"
#include "mannequin/render/renderer.hpp"
#include "mannequin/math/frame.hpp"
#include "mannequin/render/view.hpp"

namespace mannequin::render {
namespace {

// Colour classes of the default Style under the renderer's shading (factor 0.35 to 1 of the base colour).
bool isMannequinBlue(const std::array<std::uint8_t, 3>& c) {
  return c[2] > 60 && c[2] > 1.6 * c[0] && c[2] > 1.3 * c[1];
}
bool isForce(const std::array<std::uint8_t, 3>& c) { return c[0] > 80 && c[0] >= c[1] && 3 * c[2] < c[0]; }

struct Box {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  void add(const Eigen::Vector2d& p) {
    x0 = std::min(x0, p.x()); y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x()); y1 = std::max(y1, p.y());
  }
  bool contains(double x, double y, double margin) const {
    return x >= x0 - margin && x <= x1 + margin && y >= y0 - margin && y <= y1 + margin;
  }
};

// The pixel box of a sphere-swept set of points (each point ± r along the world axes).
void addSwept(Box& box, const Camera& cam, const Vec3& p, double r, int w, int h) {
  for (int a = 0; a < 3; ++a)
    for (int s = -1; s <= 1; s += 2) box.add(cam.pixel(p + s * r * Vec3::Unit(a), w, h));
}

class Headless : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      ctx_ = std::make_unique<HeadlessContext>(kW, kH);
      renderer_ = std::make_unique<Renderer>();
    } catch (const RenderError& e) {
      GTEST_SKIP() << "no headless OpenGL 3.3 here (" << e.what() << "); tools/setup installs Mesa's EGL";
    }
  }
  void TearDown() override {
    if (ctx_) ctx_->makeCurrent();
    renderer_.reset();
    ctx_.reset();
  }
  Image render(const RenderScene& s, const Camera& cam) {
    ctx_->makeCurrent();
    renderer_->draw(s, cam, kW, kH, {0.11f, 0.12f, 0.14f});
    return ctx_->read();
  }
  static constexpr int kW = 320, kH = 240;
  std::unique_ptr<HeadlessContext> ctx_;
  std::unique_ptr<Renderer> renderer_;
};

class Scenes : public Headless {
 protected:
  void SetUp() override {
    Headless::SetUp();
    if (IsSkipped()) return;
    model_ = std::make_unique<skeleton::Model>(testing::male50());
    assets_.scene = collision::loadScene(testing::sourcePath("configs/scenes/floor.yaml"));
    assets_.addModel(model_->name, *model_);
    ms_ = testing::addMannequin(ws_, *model_, skeleton::standingConfiguration(*model_), "alice");
    orbit_.target = Vec3(0, 0, 0.9);
    orbit_.distance = 3.2;
    orbit_.yaw = 0.0;      // the eye on +x, looking along −x: world +y is image right
    orbit_.pitch = 0.1;
    cam_ = orbit_.camera(static_cast<double>(kW) / kH);
  }
  std::unique_ptr<skeleton::Model> model_;
  SceneAssets assets_;
  v1::WorldState ws_;
  v1::MannequinState* ms_ = nullptr;
  OrbitCamera orbit_;
  Camera cam_;
};

TEST_F(Headless, ContextIsOpenGL33CoreAndReportsItsRenderer) {
  const std::string d = Renderer::describeContext();
  EXPECT_NE(d.find('|'), std::string::npos);
  std::printf("headless context: %s\n", d.c_str());
}

TEST_F(Scenes, MannequinColourOccupiesTheProjectedRegionOfItsCapsules) {
  const RenderScene scene = buildScene(ws_, assets_);
  const Image img = render(scene, cam_);
  Box expected;
  for (const Primitive& p : scene.solids) {
    if (p.layer != Layer::kMannequin) continue;
    const Vec3 half = p.kind == Kind::kCapsule ? Vec3(0.5 * p.length * p.pose.R.col(2)) : Vec3::Zero();
    addSwept(expected, cam_, p.pose.p - half, p.radius, kW, kH);
    addSwept(expected, cam_, p.pose.p + half, p.radius, kW, kH);
  }
  Box seen;
  int blue = 0, outside = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (isMannequinBlue(img.at(x, y))) {
        ++blue;
        seen.add({x + 0.5, y + 0.5});
        if (!expected.contains(x + 0.5, y + 0.5, 1.5)) ++outside;
      }
  EXPECT_EQ(outside, 0);
  // the figure spans (almost) its whole projected height: head to feet are drawn
  EXPECT_GT(seen.y1 - seen.y0, 0.9 * (expected.y1 - expected.y0));
  EXPECT_GT(blue, 1500);  // ≈ a 1.75 m figure at ~290 px/m: thousands of pixels
  // and nothing blue outside the figure when the mannequin is removed
  v1::WorldState empty;
  const Image none = render(buildScene(empty, assets_), cam_);
  int blue_none = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) blue_none += isMannequinBlue(none.at(x, y)) ? 1 : 0;
  EXPECT_EQ(blue_none, 0);
}

TEST_F(Scenes, AContactForceDrawsAnArrowOfTheForceColourWhereItPointsAndNotWithoutIt) {
  const Vec3 point(0.0, 0.45, 1.2);   // beside the figure, image right
  const Vec3 force(0.0, 250.0, 0.0);  // 250 N along +y: the arrow points further right, 0.5 m long
  const Image before = render(buildScene(ws_, assets_), cam_);
  int force_before = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) force_before += isForce(before.at(x, y)) ? 1 : 0;
  EXPECT_EQ(force_before, 0);

  testing::addContact(*ms_, point, Vec3::UnitY(), force, "alice/hand_r", "wall");
  const Style style;
  const RenderScene scene = buildScene(ws_, assets_, style);
  const Image after = render(scene, cam_);
  Box arrow;
  const double len = style.force_scale * force.norm();
  addSwept(arrow, cam_, point, 2.2 * style.arrow_radius, kW, kH);
  addSwept(arrow, cam_, point + force.normalized() * len, 2.2 * style.arrow_radius, kW, kH);
  int inside = 0, outside = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (isForce(after.at(x, y))) (arrow.contains(x + 0.5, y + 0.5, 1.5) ? inside : outside)++;
  EXPECT_EQ(outside, 0);
  EXPECT_GT(inside, 0.4 * (arrow.x1 - arrow.x0) * 3);  // a shaft ≥ 3 px thick along most of its length
  // the arrow's far end is to the right of its start (+y is image right from this camera)
  EXPECT_GT(cam_.pixel(point + force.normalized() * len, kW, kH).x(), cam_.pixel(point, kW, kH).x() + 30);
}

bool isControlError(const std::array<std::uint8_t, 3>& c) { return c[0] > 200 && c[1] < 100 && c[2] > 150; }

TEST_F(Headless, AControlFrameErrorLineRunsBetweenThePoseAndTheTargetAndVanishesWhenTheyCoincide) {
  OrbitCamera orbit;
  orbit.target = Vec3(0, 0.2, 1.0);
  orbit.distance = 1.6;
  orbit.yaw = 0.0;  // +y is image right
  orbit.pitch = 0.0;
  const Camera cam = orbit.camera(static_cast<double>(kW) / kH);
  const SE3 actual(Eigen::Matrix3d::Identity(), Vec3(0, 0.0, 1.0));
  const SE3 target(Eigen::Matrix3d::Identity(), Vec3(0, 0.4, 1.1));
  v1::WorldState ws;
  v1::MannequinState* ms = ws.add_mannequins();
  ms->set_name("alice");
  testing::addControlFrame(*ms, "hand_r", actual, target);
  const Image img = render(buildScene(ws, SceneAssets{}), cam);
  const Eigen::Vector2d pa = cam.pixel(actual.p, kW, kH), pt = cam.pixel(target.p, kW, kH);
  ASSERT_GT(pt.x() - pa.x(), 60);  // the target is well to the right of the pose
  Box line;
  line.add(pa);
  line.add(pt);
  int inside = 0, outside = 0;
  double x_min = 1e9, x_max = -1e9;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (isControlError(img.at(x, y))) {
        if (!line.contains(x + 0.5, y + 0.5, 1.5)) {
          ++outside;
          continue;
        }
        ++inside;
        // on the segment between the projected points (a 1 px line)
        const Eigen::Vector2d d = (pt - pa).normalized(), r = Eigen::Vector2d(x + 0.5, y + 0.5) - pa;
        EXPECT_LT(std::abs(d.x() * r.y() - d.y() * r.x()), 1.5) << x << "," << y;
        x_min = std::min(x_min, x + 0.5);
        x_max = std::max(x_max, x + 0.5);
      }
  EXPECT_EQ(outside, 0);
  // continuous from near the pose to near the target (the axes may hide a few pixels at either end)
  EXPECT_GE(inside, 0.8 * (pt.x() - pa.x()));
  EXPECT_LT(x_min, pa.x() + 0.2 * (pt.x() - pa.x()));
  EXPECT_GT(x_max, pt.x() - 0.2 * (pt.x() - pa.x()));
  // target on the pose: no error line anywhere (its axes are still drawn)
  ms->mutable_control_frames(0)->mutable_target()->CopyFrom(ms->control_frames(0).actual());
  const Image same = render(buildScene(ws, SceneAssets{}), cam);
  int error_same = 0, axes_same = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      error_same += isControlError(same.at(x, y)) ? 1 : 0;
      axes_same += same.at(x, y) != img.at(0, 0) ? 1 : 0;
    }
  EXPECT_EQ(error_same, 0);
  EXPECT_GT(axes_same, 20);
}

TEST_F(Scenes, ALayerSwitchedOffLeavesNoPixelOfItsColour) {
  testing::addContact(*ms_, Vec3(0.0, 0.45, 1.2), Vec3::UnitY(), Vec3(0, 250, 0), "alice/hand_r", "wall");
  testing::addControlFrame(*ms_, "hand_l", SE3(Eigen::Matrix3d::Identity(), Vec3(0, -0.6, 1.0)),
                           SE3(Eigen::Matrix3d::Identity(), Vec3(0, -0.9, 1.1)));
  const auto countOf = [&](const Image& img, bool (*cls)(const std::array<std::uint8_t, 3>&)) {
    int n = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) n += cls(img.at(x, y)) ? 1 : 0;
    return n;
  };
  const RenderScene all = buildScene(ws_, assets_);
  const Image full = render(all, cam_);
  ASSERT_GT(countOf(full, isMannequinBlue), 1000);
  ASSERT_GT(countOf(full, isForce), 20);
  ASSERT_GT(countOf(full, isControlError), 10);
  // the control frame's axes are red, green and blue (the usual convention), hues the force and mannequin
  // classes also match: those two cases hide the control frames too, and look for the error line's magenta
  struct Case {
    RenderLayers layers;
    bool (*cls)(const std::array<std::uint8_t, 3>&);
    const char* what;
  };
  RenderLayers no_mannequins, no_contacts, no_control;
  no_mannequins.mannequins = no_mannequins.control_frames = false;
  no_contacts.contacts = no_contacts.control_frames = false;
  no_control.control_frames = false;
  for (const Case& c : {Case{no_mannequins, isMannequinBlue, "mannequins"}, Case{no_contacts, isForce, "contacts"},
                        Case{no_control, isControlError, "control_frames"}}) {
    RenderScene s = all;
    applyLayers(s, c.layers);
    const Image img = render(s, cam_);
    EXPECT_EQ(countOf(img, c.cls), 0) << c.what << " off";
    // the layers still on are still drawn
    if (c.layers.mannequins) {
      EXPECT_GT(countOf(img, isMannequinBlue), 1000) << c.what << " off";
    }
    if (c.layers.contacts) {
      EXPECT_GT(countOf(img, isForce), 20) << c.what << " off";
    }
  }
  // and the colour classes do not hide one another: switching off every layer but one leaves its colour
  RenderLayers only_control;
  only_control.mannequins = only_control.scene = only_control.objects = only_control.contacts = only_control.balance = false;
  RenderScene s = all;
  applyLayers(s, only_control);
  EXPECT_EQ(s.count(Layer::kControl), 3u);
  EXPECT_EQ(s.solids.size(), 3u);
  EXPECT_GT(countOf(render(s, cam_), isControlError), 10);
}

TEST_F(Scenes, AFollowingCameraKeepsAMannequinWalking2MetresNearTheImageCentre) {
  // the mannequin walks 2 m along +y (image right from this camera): its blue pixels' mean column
  const auto meanColumn = [&](const Image& img) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        if (isMannequinBlue(img.at(x, y))) { sum += x + 0.5; ++n; }
    return std::make_pair(n, n ? sum / n : -1.0);
  };
  const math::VectorX q0 = skeleton::standingConfiguration(*model_);
  double still_last = 0;
  int still_n = 0;
  for (int k = 0; k <= 4; ++k) {
    math::VectorX q = q0;
    q[1] += 0.5 * k;  // root position y
    v1::WorldState ws;
    testing::addMannequin(ws, *model_, q, "alice");
    const OrbitCamera follow = followed(orbit_, ws, "alice");
    const auto [n, x] = meanColumn(render(buildScene(ws, assets_), follow.camera(static_cast<double>(kW) / kH)));
    ASSERT_GT(n, 1000) << "step " << k;
    EXPECT_NEAR(x, 0.5 * kW, 0.05 * kW) << "step " << k;  // the figure stays centred (its pelvis is the target)
    std::tie(still_n, still_last) = meanColumn(render(buildScene(ws, assets_), cam_));
  }
  // without following, the same walk takes it out of the picture (at least most of it)
  EXPECT_TRUE(still_n < 300 || still_last > 0.85 * kW) << still_n << " px at column " << still_last;
}

TEST_F(Headless, StereoSideBySideHalvesShowCrossedParallaxInFrontOfTheWallAndUncrossedBehindIt) {
  ViewConfig view = parseView(
      "type: wall\nwall: {lower_left: [1.5, 1.5, 0], lower_right: [1.5, -1.5, 0], upper_left: [1.5, 1.5, 3]}\n"
      "head: [0, 0, 1.5]\nstereo: {eye_separation: 0.2, mode: side_by_side}\n",
      "stereo.yaml");
  const auto eyes = view.eyes(kW, kH);
  ASSERT_EQ(eyes.size(), 2u);
  // mean column (within its half) of the blue pixels of each half
  const auto columns = [&](const Image& img) {
    std::array<double, 2> sum{0, 0};
    std::array<int, 2> n{0, 0};
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        if (isMannequinBlue(img.at(x, y))) {
          const std::size_t half = x < eyes[1].x ? 0 : 1;
          sum[half] += x + 0.5 - eyes[half].x;
          ++n[half];
        }
    EXPECT_GT(n[0], 4);
    EXPECT_GT(n[1], 4);
    return std::array<double, 2>{sum[0] / std::max(1, n[0]), sum[1] / std::max(1, n[1])};
  };
  const auto ball = [](const Vec3& p, double r) {
    RenderScene s;
    Primitive b;
    b.kind = Kind::kSphere;
    b.radius = r;
    b.pose.p = p;
    b.colour = Style{}.mannequin_colours[0];
    s.solids.push_back(b);
    return s;
  };
  struct Case {
    Vec3 p;
    double r;
    int sign;  // of (left column − right column): + crossed (in front of the wall), − uncrossed (behind)
  };
  for (const Case& c : {Case{Vec3(0.6, 0, 1.5), 0.03, +1}, Case{Vec3(4.5, 0, 1.5), 0.15, -1}}) {
    ctx_->makeCurrent();
    renderer_->draw(ball(c.p, c.r), eyes, kH, {0.11f, 0.12f, 0.14f});
    const Image img = ctx_->read();
    const auto seen = columns(img);
    const double expected_left = eyes[0].camera.pixel(c.p, eyes[0].width, kH).x();
    const double expected_right = eyes[1].camera.pixel(c.p, eyes[1].width, kH).x();
    const double parallax = expected_left - expected_right;
    EXPECT_GT(c.sign * parallax, 5.0) << c.p.transpose();  // the case is meaningful: several pixels
    EXPECT_NEAR(seen[0], expected_left, 1.0) << c.p.transpose();
    EXPECT_NEAR(seen[1], expected_right, 1.0) << c.p.transpose();
    EXPECT_GT(c.sign * (seen[0] - seen[1]), 0.7 * std::abs(parallax)) << c.p.transpose();
  }
  // on the wall plane there is no parallax
  ctx_->makeCurrent();
  renderer_->draw(ball(Vec3(1.5, 0, 1.5), 0.05), eyes, kH, {0.11f, 0.12f, 0.14f});
  const auto on = columns(ctx_->read());
  EXPECT_NEAR(on[0], on[1], 1.0);
}

TEST_F(Scenes, TwoWallViewsOfOneFrameAgreeAtTheirSharedEdge) {
  const ViewConfig front = loadView(testing::sourcePath("configs/views/wall_front.yaml"));
  const ViewConfig right = loadView(testing::sourcePath("configs/views/wall_right.yaml"));
  const Vec3 head(0.3, -0.2, 1.6);
  const Vec3 edge(1.5, -1.5, 1.3);  // on the shared vertical edge
  const Vec3 p0 = head + 2.0 * (edge - head);
  const Vec3 d = ((edge - head).cross(Vec3::UnitZ()).normalized() + Vec3(0, 0, 0.3)).normalized();
  RenderScene scene;
  Primitive bar;
  bar.kind = Kind::kCapsule;
  bar.layer = Layer::kMannequin;
  bar.radius = 0.06;
  bar.length = 1.4;
  bar.pose = SE3(math::frameAlong(d), p0);
  bar.colour = Style{}.mannequin_colours[0];
  scene.solids.push_back(bar);
  const Image fi = render(scene, wallCamera(front.wall, head, 0.05, 100));
  const Image ri = render(scene, wallCamera(right.wall, head, 0.05, 100));
  const auto meanRow = [](const Image& img, int x) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      if (isMannequinBlue(img.at(x, y))) { sum += y; ++n; }
    return std::make_pair(n, n ? sum / n : -1.0);
  };
  const auto [nf, yf] = meanRow(fi, kW - 1);  // front's right border column
  const auto [nr, yr] = meanRow(ri, 0);       // right wall's left border column
  ASSERT_GT(nf, 3);
  ASSERT_GT(nr, 3);
  EXPECT_LE(std::abs(yf - yr), 2.0) << "front row " << yf << ", right row " << yr;
  EXPECT_LE(std::abs(nf - nr), 2) << "bar thickness at the edge";
}

TEST_F(Scenes, RenderingIsDeterministicAndWritesAPng) {
  testing::addContact(*ms_, Vec3(0.1, 0.1, 0.0), Vec3::UnitZ(), Vec3(0, 0, 300), "alice/foot_l", "floor");
  const RenderScene scene = buildScene(ws_, assets_);
  const Image a = render(scene, cam_);
  const Image b = render(scene, cam_);
  EXPECT_EQ(a.rgb, b.rgb);
  const std::string path = (std::filesystem::temp_directory_path() / "mannequin_render_test.png").string();
  writePng(path, a);
  std::ifstream in(path, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  EXPECT_GT(std::filesystem::file_size(path), 1000u);
  std::filesystem::remove(path);
  EXPECT_THROW(writePng("/nonexistent/dir/x.png", a), RenderError);
}

// The renderer culls the back faces of closed shapes (spheres, boxes, cylinders, cones, capsules: half
// spheres on an open cylinder). Were a shape's triangles wound the wrong way, its near faces would be culled
// and its far ones drawn: a sphere inside it would then show through. From twelve directions, a shape hides
// a sphere at its centre (a capsule one at each end's centre too) and covers the pixel of its centre.
TEST_F(Headless, ClosedShapesHideWhatIsInsideThemFromEverySide) {
  const Colour red{1, 0, 0, 1}, green{0, 1, 0, 1};
  const auto isRed = [](const std::array<std::uint8_t, 3>& c) { return c[0] > 60 && c[1] < 20 && c[2] < 20; };
  const auto isGreen = [](const std::array<std::uint8_t, 3>& c) { return c[1] > 60 && c[0] < 20 && c[2] < 20; };
  const SE3 tilted(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(0.05, -0.03, 0.02));
  struct Case {
    Kind kind;
    const char* what;
    std::vector<Vec3> inside;  // shape frame
  };
  const std::vector<Case> cases{{Kind::kSphere, "sphere", {Vec3::Zero()}},
                                {Kind::kBox, "box", {Vec3::Zero()}},
                                {Kind::kCylinder, "cylinder", {Vec3::Zero()}},
                                {Kind::kCone, "cone", {Vec3(0, 0, 0.1)}},
                                {Kind::kCapsule, "capsule", {Vec3::Zero(), Vec3(0, 0, -0.2), Vec3(0, 0, 0.2)}}};
  for (const Case& c : cases) {
    RenderScene s;
    Primitive p;
    p.kind = c.kind;
    p.pose = tilted;
    p.radius = 0.15;
    p.length = c.kind == Kind::kCone ? 0.35 : 0.4;
    p.size = Vec3(0.3, 0.25, 0.35);
    p.colour = red;
    s.solids.push_back(p);
    for (const Vec3& q : c.inside) {
      Primitive in;
      in.kind = Kind::kSphere;
      in.pose = SE3(Eigen::Matrix3d::Identity(), tilted.act(q));
      in.radius = 0.06;
      in.colour = green;
      s.solids.push_back(in);
    }
    const Vec3 centre = tilted.act(c.kind == Kind::kCone ? Vec3(0, 0, 0.1) : Vec3::Zero());
    for (double yaw : {0.0, 1.5707963, 3.1415926, -1.5707963})
      for (double pitch : {-1.2, 0.0, 1.2}) {
        OrbitCamera orbit;
        orbit.target = centre;
        orbit.distance = 1.5;
        orbit.yaw = yaw;
        orbit.pitch = pitch;
        const Camera cam = orbit.camera(static_cast<double>(kW) / kH);
        const Image img = render(s, cam);
        int red_n = 0, green_n = 0;
        for (int y = 0; y < kH; ++y)
          for (int x = 0; x < kW; ++x) {
            red_n += isRed(img.at(x, y));
            green_n += isGreen(img.at(x, y));
          }
        const Eigen::Vector2d px = cam.pixel(centre, kW, kH);
        EXPECT_EQ(green_n, 0) << c.what << " yaw " << yaw << " pitch " << pitch;
        EXPECT_GT(red_n, 500) << c.what << " yaw " << yaw << " pitch " << pitch;
        EXPECT_TRUE(isRed(img.at(static_cast<int>(px.x()), static_cast<int>(px.y()))))
            << c.what << " yaw " << yaw << " pitch " << pitch;
      }
  }
}

// Round shapes take a coarser tessellation the smaller they are on screen (at most 0.2 px from the true
// outline; the finest, 24 slices, up to ≈ 23 px of radius, beyond which it strays more). A sphere centred on
// the view axis projects to a disc of radius (h / 2) · P₁₁ · r / √(d² − r²) pixels: from 1 to 19 px, every
// pixel whose centre is more than half a pixel inside that disc is the sphere's, and none more than half a
// pixel outside it.
TEST_F(Headless, ASphereCoversItsProjectedDiscToHalfAPixelAtEverySize) {
  const auto isRed = [](const std::array<std::uint8_t, 3>& c) { return c[0] > 60 && c[1] < 20 && c[2] < 20; };
  OrbitCamera orbit;
  orbit.target = Vec3(0.1, 0.2, 0.3);
  orbit.distance = 3.0;
  const Camera cam = orbit.camera(static_cast<double>(kW) / kH);
  const Eigen::Vector2d c = cam.pixel(orbit.target, kW, kH);
  for (double r : {0.01, 0.02, 0.03, 0.04, 0.06, 0.08, 0.12, 0.2}) {
    RenderScene s;
    Primitive p;
    p.kind = Kind::kSphere;
    p.pose = SE3(Eigen::AngleAxisd(0.7, Vec3(1, -1, 2).normalized()).toRotationMatrix(), orbit.target);
    p.radius = r;
    p.colour = {1, 0, 0, 1};
    s.solids.push_back(p);
    const double r_px = 0.5 * kH * cam.projection(1, 1) * r / std::sqrt(orbit.distance * orbit.distance - r * r);
    const Image img = render(s, cam);
    int missing = 0, extra = 0, red = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const double dist = (Eigen::Vector2d(x + 0.5, y + 0.5) - c).norm();
        const bool in = isRed(img.at(x, y));
        red += in;
        missing += !in && dist < r_px - 0.5;
        extra += in && dist > r_px + 0.5;
      }
    EXPECT_EQ(missing, 0) << "r " << r << " (" << r_px << " px)";
    EXPECT_EQ(extra, 0) << "r " << r << " (" << r_px << " px)";
    EXPECT_GT(red, 0) << "r " << r << " (" << r_px << " px)";
  }
}

}  // namespace
}  // namespace mannequin::render

namespace mannequin::render {
namespace {

TEST(StrokeFont, GlyphsCoverDigitsAndLettersAndStayInTheirCell) {
  for (char c = '0'; c <= '9'; ++c) EXPECT_TRUE(hasGlyph(c)) << c;
  for (char c = 'A'; c <= 'Z'; ++c) EXPECT_TRUE(hasGlyph(c)) << c;
  EXPECT_TRUE(hasGlyph('f'));  // lower case as upper case
  EXPECT_FALSE(hasGlyph(' '));
  const std::string all = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ.:-/%";
  const float h = 20;
  const auto segs = strokeText(all, 5, 7, h);
  std::vector<int> per(all.size(), 0);
  for (const Segment2& s : segs) {
    // the character is the one whose 0.75 h advance cell holds the segment; inside its 2 × 4 grid
    const int i = static_cast<int>((std::min(s.x0, s.x1) - 5 + 1e-3f) / (0.75f * h));
    ASSERT_GE(i, 0);
    ASSERT_LT(i, static_cast<int>(all.size()));
    ++per[static_cast<std::size_t>(i)];
    const float x0 = 5 + 0.75f * h * static_cast<float>(i);
    for (float x : {s.x0, s.x1}) EXPECT_TRUE(x >= x0 - 1e-3f && x <= x0 + 0.5f * h + 1e-3f) << all[static_cast<std::size_t>(i)];
    for (float y : {s.y0, s.y1}) EXPECT_TRUE(y >= 7 - 1e-3f && y <= 7 + h + 1e-3f) << all[static_cast<std::size_t>(i)];
  }
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_GE(per[i], 1) << all[i];
  // a space advances without drawing
  EXPECT_EQ(strokeText("1 1", 0, 0, h).size(), 2 * strokeText("1", 0, 0, h).size());
  EXPECT_FLOAT_EQ(strokeText("1 1", 0, 0, h).back().x0 - strokeText("1", 0, 0, h).back().x0, 1.5f * h);
}

class OverlayPixels : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      ctx_ = std::make_unique<HeadlessContext>(kW, kH);
      renderer_ = std::make_unique<Renderer>();
    } catch (const RenderError& e) {
      GTEST_SKIP() << "no headless OpenGL 3.3 here (" << e.what() << ")";
    }
  }
  void TearDown() override {
    if (ctx_) ctx_->makeCurrent();
    renderer_.reset();
    ctx_.reset();
  }
  Image frame(const std::string& text) {
    ViewConfig view;
    renderer_->draw(RenderScene{}, view.camera(kW, kH), kW, kH, {0.1f, 0.1f, 0.1f});
    if (!text.empty()) renderer_->drawOverlay(strokeText(text, 10, 10, 16), kW, kH, {1, 1, 1, 1});
    return ctx_->read();
  }
  static bool white(const std::array<std::uint8_t, 3>& c) { return c[0] > 200 && c[1] > 200 && c[2] > 200; }
  static constexpr int kW = 200, kH = 60;
  std::unique_ptr<HeadlessContext> ctx_;
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(OverlayPixels, TextIsDrawnInsideItsBoxAndTheChangedDigitChangesOnlyItsCell) {
  const Image none = frame(""), a = frame("FRAME 0123"), b = frame("FRAME 0124");
  int lit = 0, outside = 0, before = 0;
  // "FRAME 0123": 10 cells of 12 px from x = 10, rows 10..26 (± 1 px for the line raster)
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      before += white(none.at(x, y)) ? 1 : 0;
      if (!white(a.at(x, y))) continue;
      ++lit;
      if (x < 9 || x > 10 + 10 * 12 + 1 || y < 9 || y > 27) ++outside;
    }
  EXPECT_EQ(before, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_GE(lit, 9 * 16);  // nine glyphs of at least one 16 px stroke each
  // 3 → 4: the last cell (x in [118, 130]) differs, nothing else
  int changed = 0, changed_elsewhere = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (white(a.at(x, y)) != white(b.at(x, y))) {
        ++changed;
        if (x < 10 + 9 * 12 - 1 || x > 10 + 9 * 12 + 8 + 1) ++changed_elsewhere;
      }
  EXPECT_GT(changed, 5);
  EXPECT_EQ(changed_elsewhere, 0);
}

}  // namespace
}  // namespace mannequin::render

namespace mannequin::render {
namespace {

TEST(OverlayText, StatusStaleContactsAndScenarioLines) {
  v1::WorldState ws;
  ws.set_step(1200);
  ws.set_sim_time(1.2);
  auto lines = overlayLines(ws, nullptr);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].text, "FRAME 1200  T 1.200 S");
  const OverlayLive live{59.5, 12.25};
  EXPECT_EQ(overlayLines(ws, &live)[0].text, "FRAME 1200  FPS 59.5  LATE 12.2 MS");
  // the sim's lag behind mocap needs both send times
  ws.mutable_header()->set_send_time_ns(5'000'000'000);
  EXPECT_EQ(overlayLines(ws, nullptr)[0].text, "FRAME 1200  T 1.200 S");
  ws.mutable_mocap()->set_send_time_ns(4'996'500'000);
  EXPECT_EQ(overlayLines(ws, nullptr)[0].text, "FRAME 1200  T 1.200 S  SIM LAG 3.5 MS");
  // stale contacts: the warning line, in the warning colour
  ws.set_contacts_stale(true);
  ws.set_contacts_step(1197);
  const OverlayStyle style;
  lines = overlayLines(ws, nullptr, style);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1].text, "CONTACTS STALE  3 STEPS OLD");
  EXPECT_EQ(lines[1].colour, style.warning);
  // scenario: mechanisms, frames not free by mode, occluded mocap-driven frames
  ws.set_contacts_stale(false);
  ws.add_active_mechanisms("door_hinge");
  v1::MannequinState* m = ws.add_mannequins();
  m->set_name("operator");
  for (const auto& [frame, mode, body, tracked] :
       {std::tuple{"hand_l", "constrained", "lhand", true}, std::tuple{"hand_r", "free", "rhand", false},
        std::tuple{"foot_l", "autonomous", "", false}, std::tuple{"foot_r", "constrained", "rfoot", true}}) {
    v1::ControlFrameState* cf = m->add_control_frames();
    cf->set_frame(frame);
    cf->set_mode(mode);
    cf->set_body(body);
    cf->set_tracked(tracked);
  }
  lines = overlayLines(ws, nullptr, style);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1].text, "MECHANISMS DOOR_HINGE  AUTONOMOUS FOOT_L  CONSTRAINED HAND_L FOOT_R  OCCLUDED HAND_R");
  EXPECT_EQ(lines[1].colour, style.scenario);
  ws.add_mannequins()->set_name("bob");  // several mannequins: frames carry their mannequin's name
  EXPECT_NE(overlayLines(ws, nullptr)[1].text.find("CONSTRAINED OPERATOR/HAND_L OPERATOR/FOOT_R"), std::string::npos);
  for (const char c : std::string("_,")) EXPECT_TRUE(hasGlyph(c)) << c;
}

TEST_F(OverlayPixels, TheStaleContactFlagIsDrawnInTheWarningColourOnlyWhenContactsAreStale) {
  // a 200 × 60 image: capital height 8 px, line 2 at rows 22..30
  const auto draw = [&](const v1::WorldState& ws) {
    ViewConfig view;
    renderer_->draw(RenderScene{}, view.camera(kW, kH), kW, kH, {0.1f, 0.1f, 0.1f});
    for (const auto& [segments, colour] : layoutOverlay(overlayLines(ws, nullptr), kH))
      renderer_->drawOverlay(segments, kW, kH, colour);
    return ctx_->read();
  };
  const auto orange = [](const std::array<std::uint8_t, 3>& c) { return c[0] > 200 && c[1] > 80 && c[1] < 150 && c[2] < 60; };
  v1::WorldState ws;
  ws.set_step(42);
  ws.set_contacts_step(40);
  const Image fresh = draw(ws);
  ws.set_contacts_stale(true);
  const Image stale = draw(ws);
  int orange_fresh = 0, orange_stale = 0, orange_outside = 0, lit_below_fresh = 0;
  const float h = 8.0f, top = h + 1.75f * h;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      orange_fresh += orange(fresh.at(x, y)) ? 1 : 0;
      if (y > top + h + 1 && fresh.at(x, y) != fresh.at(kW - 1, kH - 1)) ++lit_below_fresh;
      if (!orange(stale.at(x, y))) continue;
      ++orange_stale;
      if (y < top - 1 || y > top + h + 1) ++orange_outside;
    }
  EXPECT_EQ(orange_fresh, 0);
  EXPECT_EQ(lit_below_fresh, 0);  // no second line at all
  EXPECT_EQ(orange_outside, 0);   // the flag is on its line
  EXPECT_GE(orange_stale, 10 * 8);  // "CONTACTS STALE": a dozen glyphs of at least one 8 px stroke
  // the first line is the same in both
  for (int y = 0; y < static_cast<int>(top) - 1; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_EQ(fresh.at(x, y), stale.at(x, y)) << x << "," << y;
}

}  // namespace
}  // namespace mannequin::render
