// Images without GL: PNG written and read back, contact sheets (render::tile).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "mannequin/render/renderer.hpp"

namespace mannequin::render {
namespace {

namespace fs = std::filesystem;

Image filled(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < im.rgb.size(); i += 3) {
    im.rgb[i] = r;
    im.rgb[i + 1] = g;
    im.rgb[i + 2] = b;
  }
  return im;
}

fs::path tempFile(const std::string& name) { return fs::temp_directory_path() / ("mannequin-image-" + std::to_string(::getpid()) + "-" + name); }

TEST(Image, APngReadsBackPixelForPixel) {
  Image im = filled(7, 5, 10, 20, 30);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) im.rgb[3 * static_cast<std::size_t>(y * 7 + x)] = static_cast<std::uint8_t>(x * 30 + y);
  const fs::path p = tempFile("a.png");
  writePng(p.string(), im);
  const Image back = readPng(p.string());
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgb, im.rgb);
  fs::remove(p);
}

TEST(Image, ReadingAMissingTruncatedOrForeignFileNamesIt) {
  const fs::path missing = tempFile("missing.png"), text = tempFile("text.png"), cut = tempFile("cut.png");
  std::ofstream(text) << "not a png at all";
  writePng(cut.string(), filled(64, 64, 1, 2, 3));
  fs::resize_file(cut, fs::file_size(cut) / 2);
  for (const auto& [path, what] : {std::pair{missing, "cannot open"}, std::pair{text, "not a PNG"}, std::pair{cut, "truncated"}}) {
    try {
      (void)readPng(path.string());
      ADD_FAILURE() << "read " << path;
    } catch (const RenderError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
  fs::remove(text);
  fs::remove(cut);
}

// Five 4×3 images, 3 per row, gap 2: a 3 × 2 grid of 3·4 + 4·2 = 20 by 2·3 + 3·2 = 12 pixels; image k's
// top-left pixel at (2 + (k % 3)·6, 2 + (k / 3)·5); the gaps and the empty sixth cell are background.
TEST(Image, TilePlacesImagesLeftToRightTopToBottomWithGaps) {
  std::vector<Image> images;
  for (int k = 0; k < 5; ++k) images.push_back(filled(4, 3, static_cast<std::uint8_t>(10 * (k + 1)), 0, 0));
  const Image sheet = tile(images, 3, 2, {0, 255, 0});
  ASSERT_EQ(sheet.width, 20);
  ASSERT_EQ(sheet.height, 12);
  for (int y = 0; y < sheet.height; ++y)
    for (int x = 0; x < sheet.width; ++x) {
      int which = -1;
      for (int k = 0; k < 5; ++k) {
        const int x0 = 2 + (k % 3) * 6, y0 = 2 + (k / 3) * 5;
        if (x >= x0 && x < x0 + 4 && y >= y0 && y < y0 + 3) which = k;
      }
      const auto c = sheet.at(x, y);
      if (which >= 0)
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{static_cast<std::uint8_t>(10 * (which + 1)), 0, 0})) << x << "," << y;
      else
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{0, 255, 0})) << x << "," << y;
    }
  // fewer images than columns: one row of them
  EXPECT_EQ(tile({images[0], images[1]}, 6, 0, {0, 0, 0}).width, 8);
}

TEST(Image, TileRefusesNothingMixedSizesAndBadColumns) {
  EXPECT_THROW((void)tile({}, 2, 1, {0, 0, 0}), RenderError);
  EXPECT_THROW((void)tile({filled(4, 3, 0, 0, 0), filled(3, 4, 0, 0, 0)}, 2, 1, {0, 0, 0}), RenderError);
  EXPECT_THROW((void)tile({filled(4, 3, 0, 0, 0)}, 0, 1, {0, 0, 0}), RenderError);
  EXPECT_THROW((void)tile({filled(4, 3, 0, 0, 0)}, 1, -1, {0, 0, 0}), RenderError);
}

}  // namespace
}  // namespace mannequin::render
