// mannequin-mjcf: writes a mannequin (configs/mannequins/*.yaml) as MuJoCo MJCF: bodies nested as the
// joint tree, hinge/ball/free joints, the segments' inertials and collision capsules (feet as boxes),
// a floor (skeleton::toMjcf, docs/performance.md "MuJoCo comparison").
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include "mannequin/core/main.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/mjcf.hpp"

namespace sk = mannequin::skeleton;
namespace core = mannequin::core;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-mjcf: export a mannequin config as MuJoCo MJCF (XML).\n"
               "Exit codes: 0 written, 2 bad command line or bad mannequin file (FILE:LINE: message), 1 I/O error."};
  std::string mannequin = "configs/mannequins/male_50th.yaml", out = "-";
  sk::MjcfOptions opt;
  bool no_floor = false, capsule_feet = false;
  double gz = opt.gravity.z();
  app.add_option("--mannequin,-m", mannequin, "mannequin config (configs/mannequins/*.yaml)")->capture_default_str();
  app.add_option("--out,-o", out, "output file, - for stdout")->capture_default_str();
  app.add_option("--timestep", opt.timestep, "MuJoCo timestep (s)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--gravity", gz, "gravity along z (m/s²)")->capture_default_str();
  app.add_flag("--no-floor", no_floor, "no floor plane");
  app.add_flag("--capsule-feet", capsule_feet, "feet as capsules (default: boxes, as the collision world)");
  app.add_flag("--self-collision", opt.self_collision, "contacts between the mannequin's own geoms");
  return core::runMain(app, argc, argv, [&]() -> int {
    sk::Model model;
    try {
      model = sk::buildMannequin(sk::loadMannequinSpec(mannequin));
    } catch (const std::exception& e) {  // a bad file: its FILE:LINE message, exit 2 (as mannequin-simulate)
      std::fprintf(stderr, "mannequin-mjcf: %s\n", e.what());
      return core::kExitUsage;
    }
    opt.floor = !no_floor;
    opt.foot_boxes = !capsule_feet;
    opt.gravity = sk::Vector3(0, 0, gz);
    const std::string xml = sk::toMjcf(model, opt);
    if (out == "-") {
      std::cout << xml;
      return std::cout ? core::kExitOk : core::kExitFailure;
    }
    std::ofstream f(out);
    f << xml;
    f.close();
    if (!f) {
      std::fprintf(stderr, "mannequin-mjcf: cannot write '%s'\n", out.c_str());
      return core::kExitFailure;
    }
    std::fprintf(stderr, "mannequin-mjcf: %s: %zu bodies, %.3f kg -> %s\n", model.name.c_str(), model.joints.size(),
                 model.totalMass(), out.c_str());
    return core::kExitOk;
  });
}
