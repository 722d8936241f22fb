#pragma once
/// \file renderer.hpp
/// \brief OpenGL 3.3 core renderer of a RenderScene, and the off-screen (headless) context.
///
/// OpenGL entry points come from the system's libGL/libOpenGL (Mesa exports every GL 3.3 function;
/// GL_GLEXT_PROTOTYPES), so there is no loader. The Renderer draws into whatever context and framebuffer
/// are current (a GLFW window, or the HeadlessContext's FBO).
///
/// Headless: EGL on Mesa's "surfaceless" platform (EGL_MESA_platform_surfaceless) with a configless
/// OpenGL 3.3 core context and an FBO (RGBA8 colour + 24-bit depth renderbuffers). It needs no X server
/// and no DISPLAY, so tests and `--headless` run the same on a build host, in CI and under a desktop session;
/// with no GPU, Mesa answers with llvmpipe (software). Rendering is deterministic for a given Mesa build.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/render/camera.hpp"
#include "mannequin/render/scene.hpp"
#include "mannequin/render/view.hpp"

#include "mannequin/render/overlay.hpp"

namespace mannequin::render {

/// A failure of the OpenGL or EGL layer (no context, a shader that does not compile, an incomplete FBO).
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An 8-bit RGB image, rows from the TOP.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 · width · height
  std::array<std::uint8_t, 3> at(int x, int y) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

/// How writePng trades file size for time. kSmall: libpng's defaults (zlib level 6, every row filter
/// tried per row). kFast: zlib level 1 with run-length matching and the Up filter only, about 4× faster
/// and a fifth larger on rendered frames (bench-render BM_WritePng); the pixels are the same (PNG is lossless). Live headless nodes use kFast (the
/// PNG is written before the frame counts as swapped).
enum class PngSpeed { kSmall, kFast };
/// Writes an 8-bit RGB PNG (libpng). \throws RenderError naming the file.
void writePng(const std::string& path, const Image& image, PngSpeed speed = PngSpeed::kSmall);
/// Reads a PNG (any bit depth and colour type libpng converts: palette, grey, alpha dropped, 16-bit
/// stripped) as 8-bit RGB. \throws RenderError naming the file (missing, not a PNG, truncated).
Image readPng(const std::string& path);

/// A contact sheet: `images` (all of one size) left to right, top to bottom, `columns` per row, with `gap`
/// pixels of `background` between them and around them. A last row that is not full stays background.
/// \throws RenderError for no images, images of different sizes, columns < 1 or gap < 0.
Image tile(const std::vector<Image>& images, int columns, int gap, const std::array<std::uint8_t, 3>& background);

/// Draws RenderScenes with a camera into the current GL context. Build it with the context current;
/// destroy it with the same context current.
class Renderer {
 public:
  /// Compiles the shaders and uploads the unit meshes. \throws RenderError (no current context, GL < 3.3).
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Clears the current framebuffer's viewport (0, 0, width, height) to `background` and draws the scene.
  void draw(const RenderScene& scene, const Camera& camera, int width, int height,
            const std::array<float, 3>& background);
  /// The same into the viewport of columns [x, x + width) and rows [y, y + height) from the BOTTOM (GL's),
  /// clearing only that rectangle (a stereo eye's half of the image).
  void draw(const RenderScene& scene, const Camera& camera, int x, int y, int width, int height,
            const std::array<float, 3>& background);
  /// Every eye of `eyes` (ViewConfig::eyes) into a height-pixel-high image.
  void draw(const RenderScene& scene, const std::vector<EyeView>& eyes, int height, const std::array<float, 3>& background);

  /// Draws 2D line segments in pixels (rows from the top; see overlay.hpp) over what the framebuffer
  /// holds (no clear, no depth test), in `colour`. Call after draw() with the same size.
  void drawOverlay(const std::vector<Segment2>& segments, int width, int height, const Colour& colour);
  /// The same in the viewport of columns [x, x + width), all `height` rows (pixels relative to it): a stereo
  /// eye's half, so that the text is in both eyes' images at the same place (on the screen plane).
  void drawOverlay(const std::vector<Segment2>& segments, int x, int width, int height, const Colour& colour);

  /// What the last draw() (all eyes of the last draw(scene, eyes, ...)) sent to GL: draw calls and triangles
  /// of the solids (lines and the overlay not counted). bench-render reports them.
  struct Stats {
    int draw_calls = 0;
    long triangles = 0;
  };
  const Stats& stats() const { return stats_; }

  /// GL_RENDERER and GL_VERSION of the current context ("llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core Profile) Mesa ...").
  static std::string describeContext();

 private:
  struct Mesh {
    unsigned vao = 0, vbo = 0, ebo = 0;  // ebo ≠ 0: indexed (count indices), else count vertices
    int count = 0;
  };
  Mesh upload(const std::vector<float>& interleaved);  // x y z nx ny nz per vertex, triangles
  Mesh upload(const std::vector<float>& interleaved, const std::vector<unsigned>& indices);  // indexed triangles
  void drawMesh(const Mesh& mesh, const Eigen::Matrix4d& model, const Colour& colour, bool closed);
  const Mesh& meshFor(const collision::TriangleMesh& m);
  /// Tessellation of round shapes (spheres, capsules, cylinders, cones): level 0 is the finest. A shape
  /// takes the coarsest level whose polygon strays at most kMaxSagittaPx pixels from the true outline
  /// (radius_px · (1 − cos(π / slices))) at its nearest point to the eye.
  struct Level {
    int slices, stacks;  // stacks even (a capsule's end is half a sphere)
  };
  static constexpr std::array<Level, 3> kLevels{{{24, 14}, {12, 8}, {8, 6}}};
  static constexpr double kMaxSagittaPx = 0.2;
  /// The level of a round shape of `radius` around the axis segment [a, b] (world frame).
  std::size_t level(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const;

  unsigned program_ = 0;
  int u_mvp_ = -1, u_normal_ = -1, u_colour_ = -1, u_unlit_ = -1, u_light_ = -1;
  unsigned flat_program_ = 0;  // one colour per draw: planes
  int u_flat_mvp_ = -1, u_flat_colour_ = -1;
  std::array<Mesh, kLevels.size()> sphere_, hemisphere_, cylinder_, tube_, cone_;  // tube: the open cylinder of a capsule
  Mesh box_, quad_;
  unsigned line_vao_ = 0, line_vbo_ = 0;
  std::map<const collision::TriangleMesh*, Mesh> meshes_;
  Eigen::Matrix4d view_proj_ = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d view_ = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d proj_ = Eigen::Matrix4d::Identity();
  double pixels_per_unit_ = 1.0;
  // GL state as last set in draw(), so that unchanged state is not sent again
  bool culling_ = false, mirrored_ = false, in_eyes_ = false;
  unsigned bound_vao_ = 0;
  Stats stats_;
};

/// An off-screen OpenGL 3.3 core context with a width × height framebuffer (see the file comment).
/// Current on the constructing thread after construction.
class HeadlessContext {
 public:
  /// \throws RenderError saying what is missing (no EGL surfaceless platform, no GL 3.3 core, FBO incomplete).
  HeadlessContext(int width, int height);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Makes the context current and binds its framebuffer.
  void makeCurrent();
  /// The framebuffer's pixels (after glFinish), rows from the top.
  Image read() const;

 private:
  int width_, height_;
  void* display_ = nullptr;
  void* context_ = nullptr;
  unsigned fbo_ = 0, colour_ = 0, depth_ = 0;
  mutable std::vector<std::uint8_t> raw_;  // read(): the RGBA pixels as GL gives them, kept between frames
};

}  // namespace mannequin::render
