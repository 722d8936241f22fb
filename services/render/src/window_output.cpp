// The window output: a GLFW window (OpenGL 3.3 core, vsync) and its input — mouse orbit, pan and zoom,
// keys 1..7 (layers), F (follow), P (pause), R (reset the camera) (mannequin/renderservice/output.hpp).
#include <GLFW/glfw3.h>

#include <cmath>
#include <cstdlib>

#include <spdlog/spdlog.h>

#include "mannequin/core/main.hpp"
#include "mannequin/renderservice/output.hpp"

namespace mannequin::renderservice {

namespace {
using Input = WindowOutput::Input;

Input& inputOf(GLFWwindow* w) { return *static_cast<Input*>(glfwGetWindowUserPointer(w)); }

void onKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  Input& in = inputOf(w);
  ViewState& s = in.state;
  if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + render::RenderLayers::kCount) {
    const int i = key - GLFW_KEY_1;
    s.layers.flag(i) = !s.layers.flag(i);
    spdlog::info("layer {} {}", render::RenderLayers::names()[static_cast<std::size_t>(i)], s.layers.flag(i) ? "on" : "off");
  } else if (key == GLFW_KEY_F && in.view->type == render::ViewConfig::Type::kDesktop) {
    s.follow = s.follow.empty() ? (in.view->follow.empty() ? std::string("0") : in.view->follow) : std::string();
    spdlog::info("follow {}", s.follow.empty() ? "off" : s.follow);
  } else if (key == GLFW_KEY_P) {
    s.paused = !s.paused;
    spdlog::info("{}", s.paused ? "paused" : "running");
  } else if (key == GLFW_KEY_R) {
    s.orbit = in.view->orbit;
  }
}
}  // namespace

WindowOutput::WindowOutput(const NodeOptions& options, const render::ViewConfig& view) : view_(view) {
  input_.state = ViewState{view.orbit, view.follow, view.layers, false};
  if (options.overlay) input_.state.layers.overlay = true;
  input_.view = &view_;
}

WindowOutput::~WindowOutput() {
  if (window_ != nullptr) glfwDestroyWindow(window_);
  if (glfw_) glfwTerminate();
}

int WindowOutput::open() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wl = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wl == nullptr || *wl == '\0')) {
    spdlog::error("no display (DISPLAY and WAYLAND_DISPLAY are not set): use --headless --out DIR to render PNG "
                  "frames off-screen");
    return core::kExitUsage;
  }
  if (glfwInit() != GLFW_TRUE) {
    spdlog::error("cannot open the display '{}' (glfwInit failed): use --headless --out DIR to render PNG frames "
                  "off-screen", x11 ? x11 : wl);
    return core::kExitUsage;
  }
  glfw_ = true;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  window_ = glfwCreateWindow(view_.width, view_.height, ("mannequin-render: " + view_.name).c_str(), nullptr, nullptr);
  if (window_ == nullptr) {
    spdlog::error("cannot create an OpenGL 3.3 core window: use --headless --out DIR");
    return core::kExitUsage;
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  spdlog::info("window {}x{} on {}", view_.width, view_.height, render::Renderer::describeContext());
  glfwSetWindowUserPointer(window_, &input_);
  glfwSetKeyCallback(window_, onKey);
  if (view_.type == render::ViewConfig::Type::kDesktop) {
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int) {
      Input& m = inputOf(w);
      if (button == GLFW_MOUSE_BUTTON_LEFT) m.left = action == GLFW_PRESS;
      if (button == GLFW_MOUSE_BUTTON_RIGHT) m.right = action == GLFW_PRESS;
    });
    glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
      Input& m = inputOf(w);
      render::OrbitCamera& orbit = m.state.orbit;
      if (m.left) orbit.rotate(-0.01 * (x - m.x), 0.01 * (y - m.y));
      if (m.right) orbit.pan(-0.002 * orbit.distance * (x - m.x), 0.002 * orbit.distance * (y - m.y));
      m.x = x;
      m.y = y;
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) { inputOf(w).state.orbit.zoom(std::pow(0.9, dy)); });
  }
  return core::kExitOk;
}

std::array<int, 2> WindowOutput::size() {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return {w, h};
}

void WindowOutput::pollEvents() { glfwPollEvents(); }

bool WindowOutput::closed() const { return glfwWindowShouldClose(window_) != 0; }

void WindowOutput::finish() { glFinish(); }

void WindowOutput::present(const Frame&) { glfwSwapBuffers(window_); }

}  // namespace mannequin::renderservice
