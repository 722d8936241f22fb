// BVH reader and forward kinematics throughput on a 10 000-frame capture built from the CMU file.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "bench_main.hpp"
#include "mannequin/skeleton/bvh.hpp"

namespace sk = mannequin::skeleton;

namespace {

constexpr int kFrames = 10000;
constexpr const char* kCapture = "data/bvh/cmu_max_131_03.bvh";

// the CMU capture's hierarchy followed by its 1102 frame lines repeated up to kFrames frames
const std::string& bigCapture() {
  static const std::string text = [] {
    const std::string path = mannequin::bench::dataFile(kCapture);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::ostringstream s;
    s << in.rdbuf();
    const std::string full = s.str();
    // split after the "Frame Time:" line; frame lines follow
    const std::size_t header_end = full.find('\n', full.find("Frame Time:")) + 1;
    std::vector<std::string> lines;
    std::istringstream body(full.substr(header_end));
    for (std::string line; std::getline(body, line);) {
      if (line.find_first_not_of(" \t\r") != std::string::npos) lines.push_back(line);
    }
    std::string header = full.substr(0, full.find("Frames:"));
    std::string out = header + "Frames: " + std::to_string(kFrames) + "\r\nFrame Time: .0083333\r\n";
    for (int f = 0; f < kFrames; ++f) out += lines[static_cast<std::size_t>(f) % lines.size()] + "\n";
    return out;
  }();
  return text;
}

void BM_BvhParse10kFrames(benchmark::State& state) {
  const std::string& text = bigCapture();
  for (auto _ : state) {
    sk::Bvh bvh = sk::parseBvh(text, "cmu_x10k");
    benchmark::DoNotOptimize(bvh.motion.data());
    if (bvh.num_frames != kFrames) state.SkipWithError("wrong frame count");
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(text.size()));
  state.counters["frames"] = kFrames;
  state.counters["MB"] = static_cast<double>(text.size()) / 1e6;
}
BENCHMARK(BM_BvhParse10kFrames)->Unit(benchmark::kMillisecond);

void BM_BvhReadFile10kFrames(benchmark::State& state) {
  const std::string& text = bigCapture();
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("bench_bvh_" + std::to_string(::getpid()) + ".bvh");
  std::ofstream(path, std::ios::binary) << text;
  for (auto _ : state) {
    sk::Bvh bvh = sk::readBvhFile(path.string());
    benchmark::DoNotOptimize(bvh.motion.data());
  }
  std::filesystem::remove(path);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_BvhReadFile10kFrames)->Unit(benchmark::kMillisecond);

// world poses of all 38 entries (31 joints + 7 End Sites) for one frame, cycling through the frames
void BM_BvhForwardKinematicsPerFrame(benchmark::State& state) {
  static const sk::Bvh bvh = sk::parseBvh(bigCapture(), "cmu_x10k");
  std::vector<mannequin::math::SE3> world(bvh.joints.size());
  int f = 0;
  for (auto _ : state) {
    sk::bvhForwardKinematics(bvh, sk::bvhFrame(bvh, f), world);
    benchmark::DoNotOptimize(world.data());
    f = (f + 1) % bvh.num_frames;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["joints"] = static_cast<double>(bvh.joints.size());
}
BENCHMARK(BM_BvhForwardKinematicsPerFrame);

// forward kinematics of the whole 10 000-frame motion
void BM_BvhForwardKinematics10kFrames(benchmark::State& state) {
  static const sk::Bvh bvh = sk::parseBvh(bigCapture(), "cmu_x10k");
  std::vector<mannequin::math::SE3> world(bvh.joints.size());
  for (auto _ : state) {
    for (int f = 0; f < bvh.num_frames; ++f) {
      sk::bvhForwardKinematics(bvh, sk::bvhFrame(bvh, f), world);
      benchmark::DoNotOptimize(world.data());
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * bvh.num_frames);
}
BENCHMARK(BM_BvhForwardKinematics10kFrames)->Unit(benchmark::kMillisecond);

}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-bvh", kCapture)
