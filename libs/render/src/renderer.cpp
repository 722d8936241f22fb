#define GL_GLEXT_PROTOTYPES 1
#include "mannequin/render/renderer.hpp"

#include <GL/gl.h>
#include <GL/glext.h>

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace mannequin::render {

namespace {

const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_mvp;
uniform mat3 u_normal;   // view-space normal matrix
out vec3 v_normal;
void main() {
  v_normal = u_normal * a_normal;
  gl_Position = u_mvp * vec4(a_pos, 1.0);
}
)";

const char* kFragment = R"(#version 330 core
in vec3 v_normal;
uniform vec4 u_colour;
uniform int u_unlit;
uniform vec3 u_light;    // view space, unit, towards the light
out vec4 frag;
void main() {
  if (u_unlit != 0) { frag = u_colour; return; }
  float d = abs(dot(normalize(v_normal), u_light));   // two-sided headlight
  frag = vec4(u_colour.rgb * (0.35 + 0.65 * d), u_colour.a);
}
)";

// Flat surfaces (planes): one normal, so the headlight's shading is one colour, computed on the CPU with
// kFragment's formula; llvmpipe then has no varyings to interpolate over the floor's many pixels.
const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_mvp;
void main() { gl_Position = u_mvp * vec4(a_pos, 1.0); }
)";

const char* kFlatFragment = R"(#version 330 core
uniform vec4 u_colour;
out vec4 frag;
void main() { frag = u_colour; }
)";

unsigned compile(GLenum type, const char* src) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw RenderError(std::string("shader compile failed: ") + log);
  }
  return s;
}

void push(std::vector<float>& v, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  for (int i = 0; i < 3; ++i) v.push_back(static_cast<float>(p[i]));
  for (int i = 0; i < 3; ++i) v.push_back(static_cast<float>(n[i]));
}

// An indexed triangle mesh: vertices (x y z nx ny nz) shared by the triangles that meet there with the same
// normal, so llvmpipe's vertex cache runs the vertex shader once per vertex, not three times per triangle.
// Triangles are counter-clockwise seen from outside (GL's front faces), so closed meshes may cull back faces.
struct Indexed {
  std::vector<float> v;
  std::vector<unsigned> i;
  unsigned add(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    push(v, p, n);
    return static_cast<unsigned>(v.size() / 6 - 1);
  }
  void tri(unsigned a, unsigned b, unsigned c) { i.insert(i.end(), {a, b, c}); }
};

// unit sphere (radius 1), or its upper half (z ≥ 0, stacks / 2 rows; stacks even) when `half`: a capsule's
// end cap, whose lower half would lie inside the capsule's cylinder and never show
Indexed sphereMesh(int slices, int stacks, bool half = false) {
  Indexed m;
  const double pi = std::numbers::pi;
  const int rows = half ? stacks / 2 : stacks;
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j <= slices; ++j) {  // column `slices` repeats column 0 (the same point, computed as before)
      const double th = pi * i / stacks, ph = 2 * pi * j / slices;
      const Eigen::Vector3d p(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      m.add(p, p);
    }
  const auto at = [&](int i, int j) { return static_cast<unsigned>(i * (slices + 1) + j); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < slices; ++j) {
      m.tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return m;
}

// cylinder radius 1, z ∈ [−0.5, 0.5], with its caps unless `open` (a capsule's, closed by the end spheres)
Indexed cylinderMesh(int slices, bool open = false) {
  Indexed m;
  const double pi = std::numbers::pi;
  const Eigen::Vector3d lo(0, 0, -0.5), hi(0, 0, 0.5);
  for (int j = 0; j <= slices; ++j) {
    const double a = 2 * pi * j / slices;
    const Eigen::Vector3d n(std::cos(a), std::sin(a), 0);
    m.add(n + lo, n);
    m.add(n + hi, n);
  }
  for (int j = 0; j < slices; ++j) {
    const unsigned l0 = static_cast<unsigned>(2 * j), h0 = l0 + 1, l1 = l0 + 2, h1 = l0 + 3;
    m.tri(l0, l1, h1);
    m.tri(l0, h1, h0);
  }
  if (open) return m;
  for (int s = -1; s <= 1; s += 2) {
    const Eigen::Vector3d n = s * Eigen::Vector3d::UnitZ(), c = s > 0 ? hi : lo;
    const unsigned centre = m.add(c, n), first = static_cast<unsigned>(m.v.size() / 6);
    for (int j = 0; j <= slices; ++j) {
      const double a = 2 * pi * j / slices;
      m.add(Eigen::Vector3d(std::cos(a), std::sin(a), 0) + c, n);
    }
    for (int j = 0; j < slices; ++j) {
      const unsigned p0 = first + static_cast<unsigned>(j), p1 = p0 + 1;
      if (s > 0) m.tri(centre, p0, p1);
      else m.tri(centre, p1, p0);
    }
  }
  return m;
}

// cone: base radius 1 at z = 0, apex at z = 1, with its base cap
Indexed coneMesh(int slices) {
  Indexed m;
  const double pi = std::numbers::pi;
  const Eigen::Vector3d apex(0, 0, 1);
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  const unsigned centre = m.add(Eigen::Vector3d::Zero(), down);
  for (int j = 0; j < slices; ++j) {
    const double a0 = 2 * pi * j / slices, a1 = 2 * pi * (j + 1) / slices;
    const Eigen::Vector3d p0(std::cos(a0), std::sin(a0), 0), p1(std::cos(a1), std::sin(a1), 0);
    const Eigen::Vector3d n0 = Eigen::Vector3d(p0.x(), p0.y(), 1).normalized(), n1 = Eigen::Vector3d(p1.x(), p1.y(), 1).normalized();
    const unsigned a = m.add(p0, n0), b = m.add(p1, n1), c = m.add(apex, (n0 + n1).normalized());
    m.tri(a, b, c);
    const unsigned d = m.add(p1, down), e = m.add(p0, down);
    m.tri(centre, d, e);
  }
  return m;
}

// cube [−0.5, 0.5]³
Indexed boxMesh() {
  Indexed m;
  for (int axis = 0; axis < 3; ++axis)
    for (int s = -1; s <= 1; s += 2) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = s;
      const Eigen::Vector3d u = Eigen::Vector3d::Unit((axis + 1) % 3), w = Eigen::Vector3d::Unit((axis + 2) % 3);
      const Eigen::Vector3d c = 0.5 * n;
      const unsigned a = m.add(c - 0.5 * u - 0.5 * w, n), b = m.add(c + 0.5 * u - 0.5 * w, n), cc = m.add(c + 0.5 * u + 0.5 * w, n),
                     d = m.add(c - 0.5 * u + 0.5 * w, n);
      // (u, w, +axis) is right-handed: a b cc is counter-clockwise seen from +axis, so the −axis face turns it
      if (s > 0) {
        m.tri(a, b, cc);
        m.tri(a, cc, d);
      } else {
        m.tri(a, cc, b);
        m.tri(a, d, cc);
      }
    }
  return m;
}

// square [−0.5, 0.5]² at z = 0, normal +z
Indexed quadMesh() {
  Indexed m;
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  const unsigned a = m.add({-0.5, -0.5, 0}, n), b = m.add({0.5, -0.5, 0}, n), c = m.add({0.5, 0.5, 0}, n), d = m.add({-0.5, 0.5, 0}, n);
  m.tri(a, b, c);
  m.tri(a, c, d);
  return m;
}

Eigen::Matrix4d poseMatrix(const SE3& pose, const Eigen::Vector3d& scale) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = pose.R * scale.asDiagonal();
  m.block<3, 1>(0, 3) = pose.p;
  return m;
}

}  // namespace

std::string Renderer::describeContext() {
  const auto* r = glGetString(GL_RENDERER);
  const auto* v = glGetString(GL_VERSION);
  return std::string(r ? reinterpret_cast<const char*>(r) : "?") + " | " + (v ? reinterpret_cast<const char*>(v) : "?");
}

Renderer::Renderer() {
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 33)
    throw RenderError("OpenGL 3.3 core is needed; the current context is " + describeContext());
  const auto link = [](const char* vertex, const char* fragment) {
    const unsigned vs = compile(GL_VERTEX_SHADER, vertex), fs = compile(GL_FRAGMENT_SHADER, fragment);
    const unsigned program = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) throw RenderError("shader link failed");
    return program;
  };
  program_ = link(kVertex, kFragment);
  flat_program_ = link(kFlatVertex, kFlatFragment);
  u_flat_mvp_ = glGetUniformLocation(flat_program_, "u_mvp");
  u_flat_colour_ = glGetUniformLocation(flat_program_, "u_colour");
  u_mvp_ = glGetUniformLocation(program_, "u_mvp");
  u_normal_ = glGetUniformLocation(program_, "u_normal");
  u_colour_ = glGetUniformLocation(program_, "u_colour");
  u_unlit_ = glGetUniformLocation(program_, "u_unlit");
  u_light_ = glGetUniformLocation(program_, "u_light");
  const auto up = [this](const Indexed& m) { return upload(m.v, m.i); };
  for (std::size_t k = 0; k < kLevels.size(); ++k) {
    const Level& l = kLevels[k];
    sphere_[k] = up(sphereMesh(l.slices, l.stacks));
    hemisphere_[k] = up(sphereMesh(l.slices, l.stacks, true));
    cylinder_[k] = up(cylinderMesh(l.slices));
    tube_[k] = up(cylinderMesh(l.slices, true));
    cone_[k] = up(coneMesh(l.slices));
  }
  box_ = up(boxMesh());
  quad_ = up(quadMesh());
  glGenVertexArrays(1, &line_vao_);
  glGenBuffers(1, &line_vbo_);
  glBindVertexArray(line_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
}

Renderer::~Renderer() {
  auto drop = [](Mesh& m) {
    if (m.vbo) glDeleteBuffers(1, &m.vbo);
    if (m.ebo) glDeleteBuffers(1, &m.ebo);
    if (m.vao) glDeleteVertexArrays(1, &m.vao);
  };
  for (std::size_t k = 0; k < kLevels.size(); ++k) {
    drop(sphere_[k]); drop(hemisphere_[k]); drop(cylinder_[k]); drop(tube_[k]); drop(cone_[k]);
  }
  drop(box_); drop(quad_);
  for (auto& [k, m] : meshes_) drop(m);
  if (line_vbo_) glDeleteBuffers(1, &line_vbo_);
  if (line_vao_) glDeleteVertexArrays(1, &line_vao_);
  if (program_) glDeleteProgram(program_);
  if (flat_program_) glDeleteProgram(flat_program_);
}

Renderer::Mesh Renderer::upload(const std::vector<float>& interleaved, const std::vector<unsigned>& indices) {
  Mesh m = upload(interleaved);
  glBindVertexArray(m.vao);
  glGenBuffers(1, &m.ebo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);  // part of the VAO's state
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(unsigned)), indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  m.count = static_cast<int>(indices.size());
  return m;
}

Renderer::Mesh Renderer::upload(const std::vector<float>& data) {
  Mesh m;
  glGenVertexArrays(1, &m.vao);
  glGenBuffers(1, &m.vbo);
  glBindVertexArray(m.vao);
  glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
  bound_vao_ = 0;
  m.count = static_cast<int>(data.size() / 6);
  return m;
}

const Renderer::Mesh& Renderer::meshFor(const collision::TriangleMesh& tm) {
  if (auto it = meshes_.find(&tm); it != meshes_.end()) return it->second;
  std::vector<float> v;
  v.reserve(tm.triangles.size() * 18);
  for (const auto& t : tm.triangles) {
    const Eigen::Vector3d a = tm.vertices[static_cast<std::size_t>(t[0])], b = tm.vertices[static_cast<std::size_t>(t[1])],
                          c = tm.vertices[static_cast<std::size_t>(t[2])];
    Eigen::Vector3d n = (b - a).cross(c - a);
    n = n.norm() > 0 ? n.normalized() : Eigen::Vector3d::UnitZ();
    push(v, a, n); push(v, b, n); push(v, c, n);
  }
  return meshes_.emplace(&tm, upload(v)).first->second;
}

void Renderer::drawMesh(const Mesh& mesh, const Eigen::Matrix4d& model, const Colour& colour, bool closed) {
  // a closed mesh shows only its front faces (the back ones are behind them): cull those, which halves what
  // llvmpipe sets up and shades. A mirroring model matrix turns the winding.
  if (closed != culling_) {
    if (closed) glEnable(GL_CULL_FACE);
    else glDisable(GL_CULL_FACE);
    culling_ = closed;
  }
  if (closed) {
    const bool mirrored = model.block<3, 3>(0, 0).determinant() < 0;
    if (mirrored != mirrored_) {
      glFrontFace(mirrored ? GL_CW : GL_CCW);
      mirrored_ = mirrored;
    }
  }
  const Eigen::Matrix4f mvp = (view_proj_ * model).cast<float>();
  const Eigen::Matrix3d mv = view_.block<3, 3>(0, 0) * model.block<3, 3>(0, 0);
  const Eigen::Matrix3f nm = mv.inverse().transpose().cast<float>();
  glUniformMatrix4fv(u_mvp_, 1, GL_FALSE, mvp.data());  // Eigen is column-major, as GL expects
  glUniformMatrix3fv(u_normal_, 1, GL_FALSE, nm.data());
  glUniform4f(u_colour_, colour[0], colour[1], colour[2], colour[3]);
  if (mesh.vao != bound_vao_) {
    glBindVertexArray(mesh.vao);
    bound_vao_ = mesh.vao;
  }
  if (mesh.ebo) glDrawElements(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT, nullptr);
  else glDrawArrays(GL_TRIANGLES, 0, mesh.count);
  ++stats_.draw_calls;
  stats_.triangles += mesh.count / 3;
}

std::size_t Renderer::level(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const {
  // the distance in front of the eye of the shape's nearest axis end, less its radius (≤ 0: the eye is at it)
  const double da = -(view_.block<3, 3>(0, 0) * a + view_.block<3, 1>(0, 3)).z();
  const double db = -(view_.block<3, 3>(0, 0) * b + view_.block<3, 1>(0, 3)).z();
  const double depth = std::min(da, db) - radius;
  const bool perspective = proj_(3, 2) != 0.0;
  if (perspective && depth <= 1e-6) return 0;
  const double px = radius * pixels_per_unit_ / (perspective ? depth : 1.0);  // radius in pixels at its nearest
  for (std::size_t k = kLevels.size(); k-- > 1;)
    if (px * (1.0 - std::cos(std::numbers::pi / kLevels[k].slices)) <= kMaxSagittaPx) return k;
  return 0;
}

void Renderer::draw(const RenderScene& scene, const Camera& camera, int width, int height,
                    const std::array<float, 3>& background) {
  draw(scene, camera, 0, 0, width, height, background);
}

void Renderer::draw(const RenderScene& scene, const std::vector<EyeView>& eyes, int height,
                    const std::array<float, 3>& background) {
  stats_ = {};
  in_eyes_ = true;
  for (const EyeView& e : eyes) draw(scene, e.camera, e.x, 0, e.width, height, background);
  in_eyes_ = false;
}

void Renderer::draw(const RenderScene& scene, const Camera& camera, int x, int y, int width, int height,
                    const std::array<float, 3>& background) {
  if (!in_eyes_) stats_ = {};
  glViewport(x, y, width, height);
  glEnable(GL_SCISSOR_TEST);
  glScissor(x, y, width, height);
  glClearColor(background[0], background[1], background[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  culling_ = false;
  mirrored_ = false;
  bound_vao_ = 0;
  view_ = camera.view;
  proj_ = camera.projection;
  view_proj_ = camera.projection * camera.view;
  // pixels per unit of (x or y) / depth, whichever is finer: a sphere's tessellation follows its size on screen
  pixels_per_unit_ = std::max(std::abs(proj_(0, 0)) * 0.5 * width, std::abs(proj_(1, 1)) * 0.5 * height);
  const Eigen::Vector3f light = Eigen::Vector3f(0.3f, 0.5f, 1.0f).normalized();
  // planes first, pushed back in depth so that shapes lying on them win; shaded as kFragment would
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glUseProgram(flat_program_);
  glBindVertexArray(quad_.vao);
  bound_vao_ = quad_.vao;
  for (const Primitive& p : scene.solids) {
    if (p.kind != Kind::kPlane) continue;
    const Eigen::Matrix4d model = poseMatrix(p.pose, {p.length, p.length, 1.0});
    const Eigen::Matrix3d nm = (view_.block<3, 3>(0, 0) * model.block<3, 3>(0, 0)).inverse().transpose();
    const float d = std::abs((nm * Eigen::Vector3d::UnitZ()).normalized().cast<float>().dot(light));
    const float shade = 0.35f + 0.65f * d;
    const Eigen::Matrix4f mvp = (view_proj_ * model).cast<float>();
    glUniformMatrix4fv(u_flat_mvp_, 1, GL_FALSE, mvp.data());
    glUniform4f(u_flat_colour_, p.colour[0] * shade, p.colour[1] * shade, p.colour[2] * shade, p.colour[3]);
    glDrawElements(GL_TRIANGLES, quad_.count, GL_UNSIGNED_INT, nullptr);
    ++stats_.draw_calls;
    stats_.triangles += quad_.count / 3;
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
  glUseProgram(program_);
  glUniform3f(u_light_, light.x(), light.y(), light.z());
  glUniform1i(u_unlit_, 0);
  for (const Primitive& p : scene.solids) {
    switch (p.kind) {
      case Kind::kPlane: break;
      case Kind::kSphere:
        drawMesh(sphere_[level(p.pose.p, p.pose.p, p.radius)], poseMatrix(p.pose, Eigen::Vector3d::Constant(p.radius)), p.colour, true);
        break;
      case Kind::kCylinder: {
        const Eigen::Vector3d half = p.pose.R.col(2) * (0.5 * p.length);
        drawMesh(cylinder_[level(p.pose.p - half, p.pose.p + half, p.radius)], poseMatrix(p.pose, {p.radius, p.radius, p.length}),
                 p.colour, true);
        break;
      }
      case Kind::kCone:
        drawMesh(cone_[level(p.pose.p, p.pose.p + p.pose.R.col(2) * p.length, p.radius)],
                 poseMatrix(p.pose, {p.radius, p.radius, p.length}), p.colour, true);
        break;
      case Kind::kBox: drawMesh(box_, poseMatrix(p.pose, p.size), p.colour, true); break;
      case Kind::kCapsule: {
        // the open cylinder and a half sphere at each end (the other halves, and the cylinder's caps, would
        // be inside the capsule); one tessellation for the three, so that their rims meet
        const Eigen::Vector3d half = p.pose.R.col(2) * (0.5 * p.length);
        const std::size_t k = level(p.pose.p - half, p.pose.p + half, p.radius);
        drawMesh(tube_[k], poseMatrix(p.pose, {p.radius, p.radius, p.length}), p.colour, true);
        for (int s = -1; s <= 1; s += 2) {
          SE3 end = p.pose;
          end.p = p.pose.p + s * half;
          if (s < 0) end.R = p.pose.R * Eigen::Vector3d(1, -1, -1).asDiagonal();  // the half sphere towards −z: turned about x
          drawMesh(hemisphere_[k], poseMatrix(end, Eigen::Vector3d::Constant(p.radius)), p.colour, true);
        }
        break;
      }
      case Kind::kMesh:  // an arbitrary mesh may be open or inconsistently wound: both faces drawn
        if (p.mesh) drawMesh(meshFor(*p.mesh), poseMatrix(p.pose, Eigen::Vector3d::Ones()), p.colour, false);
        break;
    }
  }
  glDisable(GL_CULL_FACE);
  culling_ = false;
  glFrontFace(GL_CCW);
  mirrored_ = false;
  // polylines, unlit, on top of the planes they lie on
  glUniform1i(u_unlit_, 1);
  const Eigen::Matrix4f vp = view_proj_.cast<float>();
  glUniformMatrix4fv(u_mvp_, 1, GL_FALSE, vp.data());
  const Eigen::Matrix3f id = Eigen::Matrix3f::Identity();
  glUniformMatrix3fv(u_normal_, 1, GL_FALSE, id.data());
  glBindVertexArray(line_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  for (const Polyline& l : scene.lines) {
    if (l.points.size() < 2) continue;
    std::vector<float> v;
    for (const auto& q : l.points) push(v, q, Eigen::Vector3d::UnitZ());
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(), GL_STREAM_DRAW);
    glUniform4f(u_colour_, l.colour[0], l.colour[1], l.colour[2], l.colour[3]);
    glDrawArrays(l.closed ? GL_LINE_LOOP : GL_LINE_STRIP, 0, static_cast<GLsizei>(l.points.size()));
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

void Renderer::drawOverlay(const std::vector<Segment2>& segments, int width, int height, const Colour& colour) {
  drawOverlay(segments, 0, width, height, colour);
}

void Renderer::drawOverlay(const std::vector<Segment2>& segments, int x, int width, int height, const Colour& colour) {
  if (segments.empty() || width <= 0 || height <= 0) return;
  glViewport(x, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program_);
  glUniform1i(u_unlit_, 1);
  const Eigen::Matrix4f id4 = Eigen::Matrix4f::Identity();
  glUniformMatrix4fv(u_mvp_, 1, GL_FALSE, id4.data());
  const Eigen::Matrix3f id3 = Eigen::Matrix3f::Identity();
  glUniformMatrix3fv(u_normal_, 1, GL_FALSE, id3.data());
  std::vector<float> v;
  v.reserve(segments.size() * 12);
  const auto ndc = [&](float x, float y) {
    // pixel centres: x + 0.5, rows from the top
    return Eigen::Vector3d(2.0 * (x + 0.5) / width - 1.0, 1.0 - 2.0 * (y + 0.5) / height, 0.0);
  };
  for (const Segment2& s : segments) {
    push(v, ndc(s.x0, s.y0), Eigen::Vector3d::UnitZ());
    push(v, ndc(s.x1, s.y1), Eigen::Vector3d::UnitZ());
  }
  glBindVertexArray(line_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(), GL_STREAM_DRAW);
  glUniform4f(u_colour_, colour[0], colour[1], colour[2], colour[3]);
  glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(2 * segments.size()));
  glBindVertexArray(0);
  glUseProgram(0);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace mannequin::render
