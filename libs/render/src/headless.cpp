#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstring>

#include "mannequin/render/renderer.hpp"

namespace mannequin::render {

namespace {
std::string eglErr(const char* what) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s failed (EGL error 0x%04x)", what, static_cast<unsigned>(eglGetError()));
  return buf;
}
}  // namespace

HeadlessContext::HeadlessContext(int width, int height) : width_(width), height_(height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw RenderError("headless: size " + std::to_string(width) + "x" + std::to_string(height) + " out of [1, 16384]");
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (client == nullptr || std::strstr(client, "EGL_MESA_platform_surfaceless") == nullptr)
    throw RenderError(
        "headless: EGL has no surfaceless platform (EGL_MESA_platform_surfaceless); install Mesa's EGL "
        "(tools/setup: libegl-mesa0 libgl1-mesa-dri)");
  EGLDisplay dpy = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (dpy == EGL_NO_DISPLAY) throw RenderError("headless: " + eglErr("eglGetPlatformDisplay(surfaceless)"));
  EGLint major = 0, minor = 0;
  if (!eglInitialize(dpy, &major, &minor)) throw RenderError("headless: " + eglErr("eglInitialize"));
  display_ = dpy;
  if (!eglBindAPI(EGL_OPENGL_API)) throw RenderError("headless: " + eglErr("eglBindAPI(OpenGL)"));
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (ctx == EGL_NO_CONTEXT) {
    eglTerminate(dpy);
    throw RenderError("headless: " + eglErr("eglCreateContext(OpenGL 3.3 core, no config)"));
  }
  context_ = ctx;
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    eglDestroyContext(dpy, ctx);
    eglTerminate(dpy);
    throw RenderError("headless: " + eglErr("eglMakeCurrent(no surface)"));
  }
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glGenRenderbuffers(1, &colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, colour_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "0x%04x", status);
    throw RenderError(std::string("headless: framebuffer incomplete (") + buf + ")");
  }
}

HeadlessContext::~HeadlessContext() {
  auto* dpy = static_cast<EGLDisplay>(display_);
  if (context_ != nullptr) {
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, static_cast<EGLContext>(context_));
    if (depth_) glDeleteRenderbuffers(1, &depth_);
    if (colour_) glDeleteRenderbuffers(1, &colour_);
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(dpy, static_cast<EGLContext>(context_));
  }
  // the display is not terminated: EGL displays are per process and shared by every context on them
}

void HeadlessContext::makeCurrent() {
  eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE, static_cast<EGLContext>(context_));
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
}

Image HeadlessContext::read() const {
  glFinish();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  Image img;
  img.width = width_;
  img.height = height_;
  // read RGBA, the renderbuffer's own format (Mesa copies it as is; GL_RGB would be converted pixel by pixel
  // on this thread), into a buffer kept between frames, then drop alpha and flip rows in one pass
  const std::size_t w = static_cast<std::size_t>(width_), h = static_cast<std::size_t>(height_);
  raw_.resize(w * h * 4);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, raw_.data());
  img.rgb.resize(w * h * 3);
  for (std::size_t y = 0; y < h; ++y) {  // GL rows are bottom-up
    const std::uint8_t* src = raw_.data() + (h - 1 - y) * w * 4;
    std::uint8_t* dst = img.rgb.data() + y * w * 3;
    // a pixel's 4 bytes stored at its 3-byte place: the 4th (alpha) is overwritten by the next pixel's red
    for (std::size_t x = 0; x + 1 < w; ++x) std::memcpy(dst + 3 * x, src + 4 * x, 4);
    std::memcpy(dst + 3 * (w - 1), src + 4 * (w - 1), 3);
  }
  return img;
}

}  // namespace mannequin::render
