#include <png.h>
#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <vector>

#include "mannequin/render/renderer.hpp"

namespace mannequin::render {

void writePng(const std::string& path, const Image& image, PngSpeed speed) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
    throw RenderError(path + ": not writing an empty or inconsistent image");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw RenderError(path + ": cannot open for writing: " + std::strerror(errno));
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::fclose(f);
    throw RenderError(path + ": libpng could not start");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    throw RenderError(path + ": libpng failed writing (disk full?)");
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (speed == PngSpeed::kFast) {
    png_set_compression_level(png, 1);
    png_set_compression_strategy(png, Z_RLE);  // runs of equal bytes: what Up-filtered rendered rows are
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  }
  png_write_info(png, info);
  const std::size_t row = 3 * static_cast<std::size_t>(image.width);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + static_cast<std::size_t>(y) * row));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) throw RenderError(path + ": write failed: " + std::strerror(errno));
}

Image readPng(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw RenderError(path + ": cannot open: " + std::strerror(errno));
  unsigned char sig[8] = {};
  if (std::fread(sig, 1, 8, f) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
    std::fclose(f);
    throw RenderError(path + ": not a PNG file");
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::fclose(f);
    throw RenderError(path + ": libpng could not start");
  }
  // declared before setjmp: a longjmp from libpng skips no destructor of theirs
  Image image;
  std::vector<png_bytep> rows;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(f);
    throw RenderError(path + ": a damaged or truncated PNG");
  }
  png_init_io(png, f);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_palette_to_rgb(png);
  png_set_expand_gray_1_2_4_to_8(png);
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (png_get_rowbytes(png, info) != 3 * static_cast<std::size_t>(w)) png_error(png, "unexpected row size");
  image.width = static_cast<int>(w);
  image.height = static_cast<int>(h);
  image.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = image.rgb.data() + 3 * static_cast<std::size_t>(w) * y;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(f);
  return image;
}

Image tile(const std::vector<Image>& images, int columns, int gap, const std::array<std::uint8_t, 3>& background) {
  if (images.empty()) throw RenderError("tile: no images");
  if (columns < 1 || gap < 0) throw RenderError("tile: columns must be >= 1 and gap >= 0");
  const int w = images.front().width, h = images.front().height;
  for (const Image& im : images)
    if (im.width != w || im.height != h || im.rgb.size() != 3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h))
      throw RenderError("tile: images of different sizes (" + std::to_string(w) + "x" + std::to_string(h) + " and " + std::to_string(im.width) +
                        "x" + std::to_string(im.height) + ")");
  const int n = static_cast<int>(images.size());
  const int cols = std::min(columns, n), rows = (n + cols - 1) / cols;
  Image out;
  out.width = cols * w + (cols + 1) * gap;
  out.height = rows * h + (rows + 1) * gap;
  out.rgb.resize(3 * static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height));
  for (std::size_t i = 0; i < out.rgb.size(); i += 3) std::copy(background.begin(), background.end(), out.rgb.begin() + static_cast<std::ptrdiff_t>(i));
  const std::size_t src_row = 3 * static_cast<std::size_t>(w), dst_row = 3 * static_cast<std::size_t>(out.width);
  for (int k = 0; k < n; ++k) {
    const int x0 = gap + (k % cols) * (w + gap), y0 = gap + (k / cols) * (h + gap);
    for (int y = 0; y < h; ++y)
      std::copy_n(images[static_cast<std::size_t>(k)].rgb.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * src_row), src_row,
                  out.rgb.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y0 + y) * dst_row + 3 * static_cast<std::size_t>(x0)));
  }
  return out;
}

}  // namespace mannequin::render
