/// \file main.cpp
/// \brief mannequin-bvh: summary and world poses of a BVH motion capture.
///
/// Exit codes: 0 success, 1 unreadable or malformed BVH file, 2 bad command line
/// (unknown option, missing argument, bad or out-of-range frame).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "mannequin/core/main.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/skeleton/bvh.hpp"

namespace sk = mannequin::skeleton;

namespace {

constexpr int kExitData = 1;
constexpr int kExitUsage = 2;

/// A command-line error found after CLI11's parsing (exit code 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A JSON string literal.
using mannequin::core::jsonString;
std::string num(double v) { return mannequin::core::jsonNumber(v, 9); }

/// Parses "0,100,-1" into resolved, de-duplicated frame indices (order kept).
std::vector<int> parseFrames(const sk::Bvh& bvh, const std::string& list) {
  std::vector<int> frames;
  std::vector<long long> values;
  try {
    values = mannequin::core::parseIntegerList(list);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--frames: ") + e.what());
  }
  for (const long long value : values) {
    int f = 0;
    try {
      f = sk::resolveBvhFrame(bvh, value);
    } catch (const std::out_of_range& e) {
      throw UsageError(std::string("--frames: ") + e.what());
    }
    if (std::find(frames.begin(), frames.end(), f) == frames.end()) frames.push_back(f);
  }
  return frames;
}

int runInfo(const std::string& path, bool json) {
  const sk::Bvh bvh = sk::readBvhFile(path);
  const std::string& root = bvh.joints.front().name;
  const int joints = sk::bvhJointCount(bvh);
  if (json) {
    std::printf("{\"joints\": %d, \"channels\": %d, \"frames\": %d, \"frame_time\": %s, \"root\": %s}\n", joints,
                bvh.num_channels, bvh.num_frames, num(bvh.frame_time).c_str(), jsonString(root).c_str());
    return 0;
  }
  std::printf("file:       %s\n", path.c_str());
  std::printf("root:       %s\n", root.c_str());
  std::printf("joints:     %d (+ %d End Sites)\n", joints, static_cast<int>(bvh.joints.size()) - joints);
  std::printf("channels:   %d per frame\n", bvh.num_channels);
  std::printf("frames:     %d at %s s (%.6g Hz), duration %.6g s\n", bvh.num_frames, num(bvh.frame_time).c_str(),
              1.0 / bvh.frame_time, bvh.num_frames * bvh.frame_time);
  std::printf("hierarchy:\n");
  // depth of each entry from its parent chain
  std::vector<int> depth(bvh.joints.size(), 0);
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    const sk::BvhJoint& joint = bvh.joints[j];
    if (joint.parent >= 0) depth[j] = depth[static_cast<std::size_t>(joint.parent)] + 1;
    std::string channels;
    for (const sk::BvhChannel c : joint.channels) {
      channels += channels.empty() ? "  [" : " ";
      channels += sk::bvhChannelName(c);
    }
    if (!channels.empty()) channels += ']';
    std::printf("  %*s%s  offset (%s, %s, %s)%s\n", 2 * depth[j], "",
                joint.end_site ? "End Site" : joint.name.c_str(), num(joint.offset.x()).c_str(),
                num(joint.offset.y()).c_str(), num(joint.offset.z()).c_str(),
                channels.c_str());
  }
  return 0;
}

int runPoses(const std::string& path, const std::string& frame_list, bool json) {
  const sk::Bvh bvh = sk::readBvhFile(path);
  const std::vector<int> frames = parseFrames(bvh, frame_list);
  std::vector<mannequin::math::SE3> world(bvh.joints.size());
  std::string out = json ? "{" : "";
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const int f = frames[k];
    sk::bvhForwardKinematics(bvh, sk::bvhFrame(bvh, f), world);
    if (json) {
      out += (k ? ", \"" : "\"") + std::to_string(f) + "\": {";
    } else {
      out += "frame " + std::to_string(f) + " (t = " + num(f * bvh.frame_time) + " s), file units:\n";
    }
    bool first = true;
    for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
      if (bvh.joints[j].end_site) continue;
      const auto& H = world[j];
      if (json) {
        out += (first ? "" : ", ") + jsonString(bvh.joints[j].name) + ": {\"p\": [" + num(H.p.x()) + ", " +
               num(H.p.y()) + ", " + num(H.p.z()) + "], \"R\": [";
        for (int r = 0; r < 3; ++r) {
          out += (r ? ", [" : "[") + num(H.R(r, 0)) + ", " + num(H.R(r, 1)) + ", " + num(H.R(r, 2)) + "]";
        }
        out += "]}";
      } else {
        char line[512];
        std::snprintf(line, sizeof line, "  %-24s p = (%10.4f, %10.4f, %10.4f)  R = [%7.4f %7.4f %7.4f; %7.4f %7.4f %7.4f; %7.4f %7.4f %7.4f]\n",
                      bvh.joints[j].name.c_str(), H.p.x(), H.p.y(), H.p.z(), H.R(0, 0), H.R(0, 1), H.R(0, 2),
                      H.R(1, 0), H.R(1, 1), H.R(1, 2), H.R(2, 0), H.R(2, 1), H.R(2, 2));
        out += line;
      }
      first = false;
    }
    if (json) out += "}";
  }
  if (json) out += "}\n";
  std::fputs(out.c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-bvh: inspect a BVH motion capture (hierarchy, frames, world poses by forward kinematics).\n"
               "Exit codes: 0 ok, 1 unreadable or malformed BVH (message FILE:LINE: expected X, got 'Y'), "
               "2 bad command line.",
               "mannequin-bvh"};
  app.require_subcommand(1, 1);

  std::string info_file;
  bool info_json = false;
  CLI::App* info = app.add_subcommand("info", "Summary of a BVH file. --json prints "
                                              "{\"joints\": N, \"channels\": N, \"frames\": N, \"frame_time\": seconds, "
                                              "\"root\": \"name\"} (joints: ROOT and JOINT entries, End Sites excluded).");
  info->add_option("FILE", info_file, "BVH file")->required();
  info->add_flag("--json", info_json, "machine-readable output");

  std::string poses_file;
  std::string poses_frames;
  bool poses_json = false;
  CLI::App* poses = app.add_subcommand(
      "poses",
      "World pose of every named joint (End Sites excluded) at the listed frames, in the file's length units.\n"
      "--json prints {\"<frame>\": {\"<joint>\": {\"p\": [x, y, z], \"R\": [[r00, r01, r02], [r10, r11, r12], "
      "[r20, r21, r22]]}}}: p is the joint origin in world coordinates, R its world rotation (row-major), with "
      "global = parent * T(offset + position channels) * R(rotation channels in listed order, degrees). "
      "The <frame> key is the RESOLVED non-negative index (-1 on a 1102-frame file prints \"1101\"); "
      "repeated frames are printed once.");
  poses->add_option("FILE", poses_file, "BVH file")->required();
  poses->add_option("--frames", poses_frames,
                    "comma-separated frame indices, negative = from the end (e.g. 0,100,-1); "
                    "write --frames=-1 or --frames -1")
      ->required();
  poses->add_flag("--json", poses_json, "machine-readable output");

  // "--frames -1" would otherwise read -1 as an option: glue a negative list to its option
  std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--frames" && args[i + 1].size() > 1 && args[i + 1][0] == '-' &&
        (std::isdigit(static_cast<unsigned char>(args[i + 1][1])) != 0)) {
      args[i] += "=" + args[i + 1];
      args.erase(args.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    }
  }
  return mannequin::core::runMain(app, args, [&] {
    try {
      if (info->parsed()) return runInfo(info_file, info_json);
      return runPoses(poses_file, poses_frames, poses_json);
    } catch (const UsageError& e) {  // the outcomes the help promises, with their own messages
      std::cerr << "mannequin-bvh: " << e.what() << "\n";
      return kExitUsage;
    } catch (const sk::BvhError& e) {
      std::cerr << "mannequin-bvh: " << e.what() << "\n";
      return kExitData;
    }
  });
}
