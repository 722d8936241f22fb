// The headless output: an off-screen EGL context, PNG frames into --out, a contact sheet with --sheet
// (mannequin/renderservice/output.hpp).
#include <cstdio>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "mannequin/core/main.hpp"
#include "mannequin/renderservice/output.hpp"

namespace fs = std::filesystem;

namespace mannequin::renderservice {

namespace {
ViewState viewFileState(const render::ViewConfig& view, bool overlay) {
  ViewState s{view.orbit, view.follow, view.layers, false};
  if (overlay) s.layers.overlay = true;
  return s;
}
}  // namespace

PngOutput::PngOutput(const NodeOptions& options, const render::ViewConfig& view, bool fast)
    : options_(options), state_(viewFileState(view, options.overlay)), fast_(fast), width_(view.width), height_(view.height) {
  if (!options.size.empty()) {
    const auto s = render::parseSize(options.size);
    width_ = s[0];
    height_ = s[1];
  }
}

PngOutput::~PngOutput() = default;

int PngOutput::open() {
  if (options_.out.empty()) {
    spdlog::error("--headless needs --out DIR (where the PNG frames go)");
    return core::kExitUsage;
  }
  if (options_.sheet > 0 && (options_.frames < 1 || options_.frames > kMaxSheetFrames)) {
    spdlog::error("--sheet needs --frames K with 1 <= K <= {} (the sheet's frames are kept in memory); got --frames {}",
                  kMaxSheetFrames, options_.frames);
    return core::kExitUsage;
  }
  fs::create_directories(options_.out);
  context_ = std::make_unique<render::HeadlessContext>(width_, height_);
  spdlog::info("headless {}x{} on {}", width_, height_, render::Renderer::describeContext());
  return core::kExitOk;
}

void PngOutput::finish() { image_ = context_->read(); }

void PngOutput::present(const Frame& frame) {
  if (!image_) finish();
  char name[64];
  std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(frame.index));
  render::writePng((fs::path(options_.out) / name).string(), *image_, fast_ ? render::PngSpeed::kFast : render::PngSpeed::kSmall);
  if (options_.sheet > 0) sheet_.push_back(std::move(*image_));
  image_.reset();
}

void PngOutput::close(long long frames) {
  std::printf("wrote %lld frames (%dx%d) to %s\n", frames, width_, height_, options_.out.c_str());
  if (sheet_.empty()) return;
  const render::Image tiled = render::tile(sheet_, options_.sheet, 4, {255, 255, 255});
  const std::string path = (fs::path(options_.out) / "sheet.png").string();
  render::writePng(path, tiled);
  std::printf("wrote the contact sheet of %zu frames (%dx%d) to %s\n", sheet_.size(), tiled.width, tiled.height, path.c_str());
}

}  // namespace mannequin::renderservice
