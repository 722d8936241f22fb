// mannequin-drive: drives a mannequin with a BVH capture (orientation transfer) and prints a summary.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>

#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/bvh_drive.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin::skeleton;
namespace core = mannequin::core;

namespace {
struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Drive a mannequin with a BVH motion capture and print a summary.\n"
               "Segment orientations are transferred (calibrated on the rest poses), joint limits clamp,\n"
               "the pelvis follows the capture's root scaled to the mannequin's hip height."};
  std::string bvh_path, mannequin_path = "configs/mannequins/male_50th.yaml", map_path = "configs/mappings/cmu.yaml";
  std::string out_csv;
  bool json = false, per_segment = false;
  app.add_option("bvh", bvh_path, "BVH file")->required()->check(CLI::ExistingFile);
  app.add_option("--mannequin", mannequin_path, "mannequin config (YAML; relative paths also from the checkout)")->capture_default_str();
  app.add_option("--map", map_path, "BVH-joint to segment mapping (YAML; relative paths also from the checkout)")->capture_default_str();
  app.add_option("--out", out_csv, "write the configuration of every frame as CSV");
  app.add_flag("--json", json, "print the summary as JSON");
  app.add_flag("--segments", per_segment, "also print the orientation error of each driven segment");

  return core::runMain(app, argc, argv, [&] {
    const MannequinSpec spec = loadMannequinSpec(core::findData(mannequin_path));
    const Model model = buildMannequin(spec);
    const BvhDriveMap map = loadBvhDriveMap(core::findData(map_path));
    BvhReadOptions options;
    options.unit_scale_to_m = map.unit_scale_to_m;
    const Bvh bvh = readBvhFile(bvh_path, options);
    if (bvh.num_frames == 0) throw std::runtime_error(bvh_path + ": the capture has no frames");
    BvhDriver driver(model, bvh, map);
    Data data(model);

    std::ofstream csv;
    if (!out_csv.empty()) {
      csv.open(out_csv);
      if (!csv) throw std::runtime_error(out_csv + ": cannot write");
      csv << "frame,time";
      for (const auto& n : model.coordinateNames()) csv << ',' << n;
      csv << '\n';
      csv.precision(9);
    }

    // drive every frame and gather statistics
    Range com_z, sole_z, head_z, err_max;
    double err_mean_sum = 0, path = 0;
    std::vector<double> seg_err(driver.segmentNames().size(), 0.0), seg_max(seg_err.size(), 0.0);
    int frames_clamped = 0, clamps = 0;
    Vector3 last_pelvis = Vector3::Zero();
    const int sole_l = model.frameIndex("sole_l"), sole_r = model.frameIndex("sole_r"), head = model.frameIndex("head_top");
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < bvh.num_frames; ++f) {
      const BvhDriveFrame r = driver.drive(f);
      forwardKinematics(model, data, r.q);
      centerOfMass(model, data);
      com_z.add(data.com.z());
      sole_z.add(data.oMf[sole_l].p.z());
      sole_z.add(data.oMf[sole_r].p.z());
      head_z.add(data.oMf[head].p.z());
      err_max.add(r.max_error_deg);
      err_mean_sum += r.mean_error_deg;
      for (size_t k = 0; k < seg_err.size(); ++k) {
        seg_err[k] += r.error_deg[k] / bvh.num_frames;
        seg_max[k] = std::max(seg_max[k], r.error_deg[k]);
      }
      frames_clamped += r.clamped > 0;
      clamps += r.clamped;
      const Vector3 pelvis = data.oMi[0].p;
      if (f > 0) path += Vector3(pelvis.x() - last_pelvis.x(), pelvis.y() - last_pelvis.y(), 0).norm();
      last_pelvis = pelvis;
      if (csv) {
        csv << f << ',' << f * bvh.frame_time;
        for (int k = 0; k < model.nq; ++k) csv << ',' << r.q(k);
        csv << '\n';
      }
    }
    const double us_per_frame =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / bvh.num_frames;

    const double duration = bvh.num_frames * bvh.frame_time;
    if (json) {
      std::cout.precision(6);
      std::cout << "{\"bvh\": \"" << bvh_path << "\", \"frames\": " << bvh.num_frames << ", \"duration_s\": " << duration
                << ", \"mannequin\": \"" << model.name << "\", \"dof\": " << model.nv << ", \"scale\": " << driver.scale()
                << ", \"orientation_error_deg\": {\"mean\": " << err_mean_sum / bvh.num_frames << ", \"max\": " << err_max.hi
                << "}, \"frames_with_clamped_joints\": " << frames_clamped << ", \"clamped_coordinates\": " << clamps
                << ", \"com_height_m\": [" << com_z.lo << ", " << com_z.hi << "], \"sole_height_m\": [" << sole_z.lo << ", "
                << sole_z.hi << "], \"head_height_max_m\": " << head_z.hi << ", \"pelvis_path_m\": " << path
                << ", \"us_per_frame\": " << us_per_frame << "}\n";
    } else {
      std::printf("capture    %s: %d frames, %.3f s at %.1f Hz\n", bvh_path.c_str(), bvh.num_frames, duration,
                  1.0 / bvh.frame_time);
      std::printf("mannequin  %s: %.3f m, %.1f kg, %d DoF (6 root + %d internal), %zu segments\n", model.name.c_str(),
                  spec.stature, model.totalMass(), model.nv, model.nv - 6, model.segments.size());
      std::printf("transfer   map '%s', %zu segments driven, root scaled by %.3f\n", map.name.c_str(), map.segments.size(),
                  driver.scale());
      std::printf("tracking   segment orientation error: mean %.2f deg, worst frame %.2f deg\n",
                  err_mean_sum / bvh.num_frames, err_max.hi);
      std::printf("limits     %d of %d frames clamped some joint (%d coordinate clamps in all)\n", frames_clamped,
                  bvh.num_frames, clamps);
      std::printf("body       CoM height %.3f..%.3f m, soles %.3f..%.3f m, head top up to %.3f m, pelvis path %.2f m\n",
                  com_z.lo, com_z.hi, sole_z.lo, sole_z.hi, head_z.hi, path);
      std::printf("speed      %.1f us per frame (transfer + kinematics)\n", us_per_frame);
      if (per_segment)
        for (size_t k = 0; k < seg_err.size(); ++k)
          std::printf("  %-12s orientation error mean %6.2f deg, max %6.2f deg\n", driver.segmentNames()[k].c_str(),
                      seg_err[k], seg_max[k]);
      if (!out_csv.empty()) std::printf("wrote      %s (%d rows x %d coordinates)\n", out_csv.c_str(), bvh.num_frames, model.nq);
    }
    return 0;
  });
}
