#pragma once
/// \file output.hpp
/// \brief Where a render node's frames go: PNG files (headless, an off-screen EGL context: the same input
/// gives the same files) or a GLFW window (needs a display; mouse and keys move the camera, toggle the
/// layers, follow and pause).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/render/renderer.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/renderservice/frame_source.hpp"
#include "mannequin/renderservice/options.hpp"

struct GLFWwindow;

namespace mannequin::renderservice {

/// How the frames are drawn: the view file's camera, follow and layers (with --overlay), which a window's
/// user changes (docs/render.md "Keys").
struct ViewState {
  render::OrbitCamera orbit;
  std::string follow;
  render::RenderLayers layers;
  bool paused = false;  ///< P: the drawn state is frozen
};

class Output {
 public:
  virtual ~Output() = default;
  /// Makes the GL context current; core::kExitOk, or core::kExitUsage after logging why it cannot (no --out,
  /// no display, ...). \throws render::RenderError when a headless context cannot be made.
  virtual int open() = 0;
  virtual std::array<int, 2> size() = 0;  ///< of the image drawn now
  virtual const ViewState& state() const = 0;
  virtual void pollEvents() {}               ///< a window's input
  virtual bool closed() const { return false; }  ///< a window closed by its user
  /// The frame is drawn (before the swap barrier): the pixels read, or the GPU done.
  virtual void finish() = 0;
  /// Shows the frame drawn: writes frame_<index>.png, or swaps the window's buffers.
  virtual void present(const Frame& frame) = 0;
  /// The run is over after `frames` frames (headless: says what it wrote, writes the contact sheet).
  virtual void close(long long frames) { (void)frames; }
};

/// PNG frames in --out (frame_NNNNNN.png, N = Frame::index), --size or the view's size; --sheet also tiles
/// them into DIR/sheet.png. `fast`: PngSpeed::kFast (synchronised nodes write at the swap).
class PngOutput final : public Output {
 public:
  PngOutput(const NodeOptions& options, const render::ViewConfig& view, bool fast);
  ~PngOutput() override;
  int open() override;
  std::array<int, 2> size() override { return {width_, height_}; }
  const ViewState& state() const override { return state_; }
  void finish() override;
  void present(const Frame& frame) override;
  void close(long long frames) override;

 private:
  const NodeOptions& options_;
  ViewState state_;
  bool fast_;
  int width_, height_;
  std::unique_ptr<render::HeadlessContext> context_;
  std::optional<render::Image> image_;  // read by finish(), written by present()
  std::vector<render::Image> sheet_;
};

/// A GLFW window with an OpenGL 3.3 core context, of the view's size; vsync.
class WindowOutput final : public Output {
 public:
  WindowOutput(const NodeOptions& options, const render::ViewConfig& view);
  ~WindowOutput() override;
  int open() override;
  std::array<int, 2> size() override;
  const ViewState& state() const override { return input_.state; }
  void pollEvents() override;
  bool closed() const override;
  void finish() override;
  void present(const Frame& frame) override;

  /// The window's input: mouse orbit, pan, zoom; keys 1..7, F, P, R.
  struct Input {
    ViewState state;
    const render::ViewConfig* view = nullptr;
    double x = 0, y = 0;
    bool left = false, right = false;
  };

 private:
  const render::ViewConfig& view_;
  Input input_;
  GLFWwindow* window_ = nullptr;
  bool glfw_ = false;
};

}  // namespace mannequin::renderservice
