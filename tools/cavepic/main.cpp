// mannequin-cavepic LEFT.png FRONT.png RIGHT.png OUT.png [GAP]
// The three walls of a CAVE unfolded into one image: left | front | right, as seen from inside the room, so
// the left wall's right edge meets the front wall's left edge and the front's right edge the right wall's
// left edge (configs/views/wall_*.yaml). GAP (default 4) pixels of white mark each shared edge. The images
// must have the same height. Exit 2 on bad usage, 1 on an unreadable or mismatched image (naming the file).
#include <png.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

struct Rgb {
  int width = 0, height = 0;
  std::vector<unsigned char> px;  // 3 · width · height, rows top-down
};

bool readPng(const char* path, Rgb& out) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&img, path) == 0) {
    std::fprintf(stderr, "mannequin-cavepic: %s: %s\n", path, img.message);
    return false;
  }
  img.format = PNG_FORMAT_RGB;
  out.width = static_cast<int>(img.width);
  out.height = static_cast<int>(img.height);
  out.px.resize(PNG_IMAGE_SIZE(img));
  if (png_image_finish_read(&img, nullptr, out.px.data(), 0, nullptr) == 0) {
    std::fprintf(stderr, "mannequin-cavepic: %s: %s\n", path, img.message);
    png_image_free(&img);
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: mannequin-cavepic LEFT.png FRONT.png RIGHT.png OUT.png [GAP]\n"
                         "  the three walls unfolded (left | front | right) with GAP (4) white pixels at the shared edges\n");
    return 2;
  }
  const int gap = argc == 6 ? std::atoi(argv[5]) : 4;
  if (gap < 0 || gap > 100) {
    std::fprintf(stderr, "mannequin-cavepic: GAP '%s' is not in [0, 100]\n", argv[5]);
    return 2;
  }
  Rgb wall[3];
  for (int i = 0; i < 3; ++i)
    if (!readPng(argv[1 + i], wall[i])) return 1;
  for (int i = 1; i < 3; ++i)
    if (wall[i].height != wall[0].height) {
      std::fprintf(stderr, "mannequin-cavepic: %s is %d pixels high, %s %d: the walls must have the same height\n",
                   argv[1 + i], wall[i].height, argv[1], wall[0].height);
      return 1;
    }
  Rgb out;
  out.width = wall[0].width + wall[1].width + wall[2].width + 2 * gap;
  out.height = wall[0].height;
  out.px.assign(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3, 255);
  int x0 = 0;
  for (const Rgb& w : wall) {
    for (int y = 0; y < w.height; ++y)
      for (int x = 0; x < 3 * w.width; ++x)
        out.px[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x0)) * 3 +
               static_cast<std::size_t>(x)] = w.px[static_cast<std::size_t>(y) * static_cast<std::size_t>(w.width) * 3 + static_cast<std::size_t>(x)];
    x0 += w.width + gap;
  }
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  img.width = static_cast<png_uint_32>(out.width);
  img.height = static_cast<png_uint_32>(out.height);
  img.format = PNG_FORMAT_RGB;
  if (png_image_write_to_file(&img, argv[4], 0, out.px.data(), 0, nullptr) == 0) {
    std::fprintf(stderr, "mannequin-cavepic: %s: %s\n", argv[4], img.message);
    return 1;
  }
  std::printf("wrote %s (%dx%d)\n", argv[4], out.width, out.height);
  return 0;
}
