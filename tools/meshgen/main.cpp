// mannequin-meshgen: generates the meshes shipped in data/meshes/ (the cockpit panel and the rotor
// part of configs/scenes/), deterministically, so that anyone can rebuild them from source.
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "mannequin/core/main.hpp"
#include "mannequin/collision/mesh.hpp"

using mannequin::collision::TriangleMesh;
using mannequin::collision::Vector3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// appends a grid surface P(i, j), i ∈ [0, nu], j ∈ [0, nv], as 2·nu·nv triangles; `flip` reverses them
template <typename F>
void grid(TriangleMesh& m, int nu, int nv, F&& P, bool flip) {
  const int base = static_cast<int>(m.vertices.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m.vertices.push_back(P(i, j));
  auto id = [&](int i, int j) { return base + j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (!flip) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, c, b});
        m.triangles.push_back({a, d, c});
      }
    }
}

/// Cockpit instrument panel, pilot's eye axis at the origin: a slab curved about the z axis
/// (front radius 0.75 m, 5 cm thick, ±40° wide, 0.45 m high from z = 0), its front face
/// carrying 12 round gauges raised 1 cm. The front faces −radial (towards the pilot).
TriangleMesh cockpitPanel(int nu, int nv) {
  TriangleMesh m;
  const double R = 0.75, t = 0.05, H = 0.45, phi = 40.0 * kPi / 180.0;
  auto bump = [&](double th, double z) {
    double h = 0.0;
    for (int gi = 0; gi < 6; ++gi)
      for (int gj = 0; gj < 2; ++gj) {
        const double cth = -phi + (gi + 0.5) * (2 * phi / 6), cz = 0.12 + gj * 0.2;
        const double dx = (th - cth) * R, dz = z - cz;
        const double r = std::sqrt(dx * dx + dz * dz);
        if (r < 0.06) h = std::max(h, 0.01 * std::min(1.0, (0.06 - r) / 0.01));  // flat top, 1 cm bevel
      }
    return h;
  };
  auto front = [&](int i, int j) {
    const double th = -phi + 2 * phi * i / nu, z = H * j / nv;
    const double r = R - bump(th, z);
    return Vector3(r * std::cos(th), r * std::sin(th), z);
  };
  auto back = [&](int i, int j) {
    const double th = -phi + 2 * phi * i / nu, z = H * j / nv;
    return Vector3((R + t) * std::cos(th), (R + t) * std::sin(th), z);
  };
  grid(m, nu, nv, front, true);   // normal towards −radial
  grid(m, nu, nv, back, false);   // normal towards +radial
  // rims: bottom/top (between front and back rows), sides
  auto ring = [&](double th, double z, double r) { return Vector3(r * std::cos(th), r * std::sin(th), z); };
  for (int side = 0; side < 2; ++side) {
    const double z = side ? H : 0.0;
    grid(m, nu, 1, [&](int i, int j) {
      const double th = -phi + 2 * phi * i / nu;
      return ring(th, z, j ? R + t : R);
    }, side == 0);
    const double th = side ? phi : -phi;
    grid(m, nv, 1, [&](int i, int j) { return ring(th, H * i / nv, j ? R + t : R); }, side == 1);
  }
  return m;
}

// a closed cylinder or tube about z, from z0 to z1 (inner radius 0: solid)
void tube(TriangleMesh& m, double r_in, double r_out, double z0, double z1, int n) {
  auto around = [&](double r, double z, int i) {
    const double a = 2 * kPi * i / n;
    return Vector3(r * std::cos(a), r * std::sin(a), z);
  };
  grid(m, n, 1, [&](int i, int j) { return around(r_out, j ? z1 : z0, i); }, false);
  if (r_in > 0) grid(m, n, 1, [&](int i, int j) { return around(r_in, j ? z1 : z0, i); }, true);
  for (int top = 0; top < 2; ++top) {
    const double z = top ? z1 : z0;
    if (r_in > 0) {
      grid(m, n, 1, [&](int i, int j) { return around(j ? r_out : r_in, z, i); }, top == 0);
    } else {
      const int c = static_cast<int>(m.vertices.size());
      m.vertices.emplace_back(0, 0, z);
      for (int i = 0; i < n; ++i) {
        const int a = static_cast<int>(m.vertices.size());
        m.vertices.push_back(around(r_out, z, i));
        m.vertices.push_back(around(r_out, z, i + 1));
        if (top) m.triangles.push_back({c, a, a + 1});
        else m.triangles.push_back({c, a + 1, a});
      }
    }
  }
}

/// Rotor-like part (a hub with four twisted blade roots): a tube (bore Ø 80 mm for the insertion
/// guide, outer Ø 240 mm, 150 mm high) and four blade roots 0.45 m long, 12° of twist each.
TriangleMesh rotorPart() {
  TriangleMesh m;
  tube(m, 0.04, 0.12, 0.0, 0.15, 64);
  const int ns = 24;
  for (int b = 0; b < 4; ++b) {
    const double az = b * kPi / 2;
    const double c0 = 0.11, c1 = 0.56, chord = 0.14, thick = 0.03, zc = 0.075;
    // cross-section corners at station s ∈ [0,1], twisted about the blade axis
    auto corner = [&](int i, int k) {
      const double s = static_cast<double>(i) / ns;
      const double twist = 12.0 * kPi / 180.0 * s;
      const double cu[4] = {-0.5 * chord, 0.5 * chord, 0.5 * chord, -0.5 * chord};
      const double cv[4] = {-0.5 * thick, -0.5 * thick, 0.5 * thick, 0.5 * thick};
      const double u = cu[k % 4] * std::cos(twist) - cv[k % 4] * std::sin(twist);
      const double v = cu[k % 4] * std::sin(twist) + cv[k % 4] * std::cos(twist);
      const double rr = c0 + (c1 - c0) * s;
      // blade axis along the azimuth; u tangential, v vertical
      return Vector3(rr * std::cos(az) - u * std::sin(az), rr * std::sin(az) + u * std::cos(az), zc + v);
    };
    grid(m, ns, 4, [&](int i, int k) { return corner(i, k); }, true);
    // tip cap
    const int base = static_cast<int>(m.vertices.size());
    for (int k = 0; k < 4; ++k) m.vertices.push_back(corner(ns, k));
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Generate the meshes shipped in data/meshes/ (cockpit panel, rotor part)."};
  std::string which = "all", out = "data/meshes";
  int nu = 96, nv = 36;
  app.add_option("what", which, "panel, rotor or all")->capture_default_str()->check(CLI::IsMember({"panel", "rotor", "all"}));
  app.add_option("--out", out, "output directory")->capture_default_str();
  app.add_option("--panel-grid", nu, "panel quads across (the panel has ~4·nu·nv triangles)")
      ->capture_default_str()->check(CLI::Range(4, 2000));
  return mannequin::core::runMain(app, argc, argv, [&] {
    nv = std::max(4, nu * 3 / 8);
    std::filesystem::create_directories(out);
    if (which == "panel" || which == "all") {
      const TriangleMesh m = cockpitPanel(nu, nv);
      const std::string path = out + "/cockpit_panel.obj";
      writeObj(m, path, "cockpit instrument panel, generated by mannequin-meshgen panel --panel-grid " + std::to_string(nu));
      spdlog::info("{}: {} vertices, {} triangles", path, m.vertices.size(), m.triangles.size());
    }
    if (which == "rotor" || which == "all") {
      const TriangleMesh m = rotorPart();
      const std::string path = out + "/rotor_part.stl";
      writeStl(m, path, "rotor part, generated by mannequin-meshgen rotor");
      spdlog::info("{}: {} vertices, {} triangles", path, m.vertices.size(), m.triangles.size());
    }
    return 0;
  });
}
