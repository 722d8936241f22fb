// mannequin-retarget: retargets a BVH capture onto a mannequin with the strict-priority IK and
// writes the mannequin's motion as BVH; prints per-level residual statistics.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/ik/retarget.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/bvh_write.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"Retarget a BVH motion capture onto a mannequin of another size (strict-priority IK:\n"
               "feet > pelvis > hands > head orientation + posture) and write the mannequin's motion as BVH."};
  std::string in_path, out_path, mannequin_path = "configs/mannequins/male_50th.yaml",
                                 map_path = "configs/mappings/cmu.yaml", calibration = "first";
  long long start = 0, end = -1;
  int max_iterations = 30;
  app.add_option("bvh", in_path, "input BVH capture")->required()->check(CLI::ExistingFile);
  app.add_option("--mannequin", mannequin_path, "mannequin config (YAML; relative paths also from the checkout)")->capture_default_str();
  app.add_option("--map", map_path, "BVH-joint to segment mapping (YAML; relative paths also from the checkout)")->capture_default_str();
  app.add_option("--out", out_path, "output BVH file (the mannequin's skeleton and motion)")->required();
  app.add_option("--calibration", calibration, "calibration pose: 'first' (first retargeted frame) or 'rest' (BVH rest pose)")
      ->capture_default_str()->check(CLI::IsMember({"first", "rest"}));
  CLI::Option* start_option = app.add_option("--start", start, "first frame (default: the first that is not a converter's T-pose)")
                                  ->check(CLI::NonNegativeNumber);
  app.add_option("--end", end, "frame after the last one (-1: to the end)")->capture_default_str();
  app.add_option("--max-iterations", max_iterations, "IK iterations per frame")->capture_default_str()->check(CLI::Range(1, 1000));

  return core::runMain(app, argc, argv, [&] {
    const skeleton::MannequinSpec spec = skeleton::loadMannequinSpec(core::findData(mannequin_path));
    const skeleton::Model model = skeleton::buildMannequin(spec);
    const skeleton::BvhDriveMap map = skeleton::loadBvhDriveMap(core::findData(map_path));
    skeleton::BvhReadOptions read_options;
    read_options.unit_scale_to_m = map.unit_scale_to_m;
    const skeleton::Bvh bvh = skeleton::readBvhFile(in_path, read_options);
    if (bvh.num_frames == 0) throw std::runtime_error(in_path + ": the capture has no frames");
    // a converter's T-pose before the capture (skeleton::bvhIsTPose) would be the calibration pose: skipped
    if (start_option->count() == 0) {
      const int tpose = skeleton::bvhLeadingTPoseFrames(bvh, 0);
      if (tpose > 0 && tpose < bvh.num_frames) {
        spdlog::info("{}: {} a T-pose (arms spread horizontally, upright): skipped, --start {}", in_path,
                     tpose > 1 ? fmt::format("frames 0..{} are", tpose - 1) : std::string("frame 0 is"), tpose);
        start = tpose;
      }
    }
    const long long last = end < 0 ? bvh.num_frames : std::min<long long>(end, bvh.num_frames);
    if (start >= last)
      throw std::runtime_error("empty frame range [" + std::to_string(start) + ", " + std::to_string(last) + ") of " +
                               std::to_string(bvh.num_frames) + " frames");
    ik::RetargetOptions options;
    options.calibration = calibration;
    options.calibration_frame = start;
    options.max_iterations = max_iterations;
    ik::Retargeter retargeter(model, bvh, map, options);
    spdlog::info("retargeting {} frames of {} onto {} ({:.3f} m, {} DoF), calibration '{}'", last - start, in_path,
                 model.name, spec.stature, model.nv, calibration);

    struct Stats {
      std::string name;
      double sum = 0, max = 0;
      long long satisfied = 0;
    };
    std::vector<Stats> stats;
    std::vector<math::VectorX> frames;
    long long iterations = 0, backtracks = 0, clamped_frames = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const long long n = last - start;
    for (long long f = start; f < last; ++f) {
      const ik::RetargetFrame r = retargeter.solve(f);
      if (stats.empty())
        for (const auto& l : r.report.levels) stats.push_back({l.name});
      for (std::size_t k = 0; k < stats.size(); ++k) {
        stats[k].sum += r.report.levels[k].residual;
        stats[k].max = std::max(stats[k].max, r.report.levels[k].residual);
        stats[k].satisfied += r.report.levels[k].satisfied;
      }
      iterations += r.report.iterations;
      backtracks += r.report.backtracks;
      clamped_frames += r.report.clamped > 0;
      frames.push_back(r.q);
      const long long done = f - start + 1;
      if (n >= 10 && done % (n / 10) == 0) spdlog::info("{:3d}% ({} / {} frames)", static_cast<int>(100 * done / n), done, n);
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    skeleton::writeMannequinBvhFile(out_path, model, frames, bvh.frame_time);

    std::printf("retargeted %lld frames of %s onto %s in %.0f ms (%.2f ms/frame, %.1f IK iterations/frame)\n", n,
                in_path.c_str(), model.name.c_str(), ms, ms / n, static_cast<double>(iterations) / n);
    std::printf("%-14s %12s %12s %10s\n", "level", "mean resid.", "max resid.", "satisfied");
    for (const auto& s : stats) {
      if (s.name == "head+posture") {
        std::printf("%-14s %12.4f %12.4f %10s\n", s.name.c_str(), s.sum / n, s.max, "(cost)");
      } else {
        std::printf("%-14s %12.5f %12.5f %9.1f%%\n", s.name.c_str(), s.sum / n, s.max, 100.0 * s.satisfied / n);
      }
    }
    std::printf("(residual: norm of the level's stacked errors, m and rad; %lld frames with a clamped joint, %lld backtracks)\n",
                clamped_frames, backtracks);
    std::printf("wrote %s (%zu joints, %lld frames)\n", out_path.c_str(), model.joints.size(), n);
    return 0;
  });
}
