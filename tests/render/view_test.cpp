// View files (configs/views/*.yaml): the shipped ones load, bad ones fail naming FILE:LINE and the key.
#include <gtest/gtest.h>

#include <filesystem>

#include "fixtures.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/render/view.hpp"

namespace mannequin::render {
namespace {

std::string errorOf(const std::string& yaml) {
  try {
    (void)parseView(yaml, "v.yaml");
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ViewConfig, ShippedViewsLoadAndTheCaveWallsShareTheirEdges) {
  const ViewConfig d = loadView(testing::sourcePath("configs/views/desktop.yaml"));
  EXPECT_EQ(d.type, ViewConfig::Type::kDesktop);
  EXPECT_EQ(d.width, 1280);
  EXPECT_NEAR(d.orbit.distance, 3.6, 1e-12);
  const ViewConfig f = loadView(testing::sourcePath("configs/views/wall_front.yaml"));
  const ViewConfig l = loadView(testing::sourcePath("configs/views/wall_left.yaml"));
  const ViewConfig r = loadView(testing::sourcePath("configs/views/wall_right.yaml"));
  for (const ViewConfig* v : {&f, &l, &r}) EXPECT_EQ(v->type, ViewConfig::Type::kWall) << v->name;
  EXPECT_LT((f.wall.lower_right - r.wall.lower_left).norm(), 1e-12);
  EXPECT_LT((f.wall.lower_left - l.wall.lower_right).norm(), 1e-12);
  // every shipped view file parses
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::sourcePath("configs/views"))) {
    EXPECT_NO_THROW((void)loadView(e.path().string())) << e.path();
    ++n;
  }
  EXPECT_GE(n, 4);
}

TEST(ViewConfig, ErrorsNameFileLineAndKey) {
  {
    const std::string e = errorOf("name: x\ntype: desktop\ncamera: {distanse: 3}\n");
    EXPECT_NE(e.find("v.yaml:3"), std::string::npos) << e;
    EXPECT_NE(e.find("distanse"), std::string::npos) << e;
  }
  EXPECT_NE(errorOf("name: x\n").find("type"), std::string::npos);
  EXPECT_NE(errorOf("type: orbit\n").find("desktop"), std::string::npos);
  EXPECT_NE(errorOf("type: desktop\ncamera: {distance: -1}\n").find("camera.distance"), std::string::npos);
  EXPECT_NE(errorOf("type: desktop\nsize: [0, 10]\n").find("size"), std::string::npos);
  EXPECT_NE(errorOf("type: wall\nhead: [0, 0, 1]\n").find("wall"), std::string::npos);
  {  // skewed wall: the error names the wall key and says why
    const std::string e = errorOf(
        "type: wall\nwall: {lower_left: [1, 1, 0], lower_right: [1, -1, 0], upper_left: [1, 0.5, 1]}\n");
    EXPECT_NE(e.find("v.yaml:2"), std::string::npos) << e;
    EXPECT_NE(e.find("orthogonal"), std::string::npos) << e;
  }
  {  // head behind the screen
    const std::string e = errorOf(
        "type: wall\nwall: {lower_left: [1, 1, 0], lower_right: [1, -1, 0], upper_left: [1, 1, 2]}\nhead: [2, 0, 1]\n");
    EXPECT_NE(e.find("behind"), std::string::npos) << e;
  }
  EXPECT_NE(errorOf("type: desktop\nwall: {}\n").find("wall"), std::string::npos);
  // a missing file names the file
  try {
    (void)loadView("/nonexistent/view.yaml");
    FAIL() << "no error";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/view.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mannequin::render
