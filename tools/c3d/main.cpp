/// \file main.cpp
/// \brief mannequin-c3d: summary, marker positions and force plates of a C3D motion capture.
///
/// Exit codes: 0 success, 2 bad input (unreadable or malformed C3D file, bad command line, bad or
/// out-of-range frame); the message is one line naming the file and what is wrong.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "mannequin/core/main.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/mocap/c3d.hpp"
#include "mannequin/mocap/force_plate.hpp"

namespace mc = mannequin::mocap;

namespace {

constexpr int kExitBadInput = 2;

/// A command-line error found after CLI11's parsing.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string jsonString(const std::string& s) { return mannequin::core::jsonString(s, true); }
std::string num(double v) { return mannequin::core::jsonNumber(v, 9); }

/// Parses "0,250,-1" into resolved, de-duplicated frame indices (order kept).
std::vector<int> parseFrames(const mc::C3d& c3d, const std::string& list) {
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
      f = mc::resolveC3dFrame(c3d, value);
    } catch (const std::out_of_range& e) {
      throw UsageError(c3d.file + ": --frames: " + e.what() + (c3d.truncated ? " (the file is truncated)" : ""));
    }
    if (std::find(frames.begin(), frames.end(), f) == frames.end()) frames.push_back(f);
  }
  return frames;
}

int runInfo(const std::string& path, bool json) {
  const mc::C3d c = mc::readC3dFile(path);
  if (json) {
    std::string out = "{\"points\": " + std::to_string(c.points) + ", \"frames\": " + std::to_string(c.framesDeclared()) +
                      ", \"rate\": " + num(c.rate) + ", \"first_frame\": " + std::to_string(c.first_frame) +
                      ", \"last_frame\": " + std::to_string(c.last_frame) + ", \"labels\": [";
    for (std::size_t i = 0; i < c.labels.size(); ++i) out += (i ? ", " : "") + jsonString(c.labels[i]);
    out += "], \"analog_per_frame\": " + std::to_string(c.analog_per_frame) + ", \"processor\": " +
           jsonString(mc::c3dProcessorName(c.processor)) + ", \"storage\": " + jsonString(mc::c3dStorageName(c.storage)) +
           ", \"scale\": " + num(c.scale) + ", \"units\": " + jsonString(c.units) +
           ", \"truncated\": " + (c.truncated ? "true" : "false") +
           ", \"frames_present\": " + std::to_string(c.frames_present) + "}\n";
    std::fputs(out.c_str(), stdout);
    return 0;
  }
  std::printf("file:       %s\n", path.c_str());
  std::printf("format:     %s processor, %s storage (scale %s)\n", mc::c3dProcessorName(c.processor),
              mc::c3dStorageName(c.storage), num(c.scale).c_str());
  std::printf("points:     %d, units '%s'\n", c.points, c.units.c_str());
  std::printf("frames:     %d (file frames %d..%d) at %s Hz, duration %.6g s\n", c.framesDeclared(), c.first_frame,
              c.last_frame, num(c.rate).c_str(), c.rate > 0 ? c.framesDeclared() / c.rate : 0.0);
  if (c.truncated) {
    std::printf("TRUNCATED:  only %d whole frames present of %d declared\n", c.frames_present, c.framesDeclared());
  }
  if (c.analog_channels > 0) {
    std::printf("analog:     %d channels x %d samples per frame at %s Hz\n", c.analog_channels, c.analog_subframes,
                num(c.analog_rate).c_str());
  } else {
    std::printf("analog:     %d samples per frame (no ANALOG:USED: not read)\n", c.analog_per_frame);
  }
  std::printf("labels:    ");
  for (const std::string& l : c.labels) std::printf(" %s", l.c_str());
  std::printf("\n");
  return 0;
}

int runPoints(const std::string& path, const std::string& frame_list, bool json) {
  const mc::C3d c = mc::readC3dFile(path);
  const std::vector<int> frames = parseFrames(c, frame_list);
  std::string out = json ? "{" : "";
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const int f = frames[k];
    if (json) {
      out += (k ? ", \"" : "\"") + std::to_string(f) + "\": {";
    } else {
      out += "frame " + std::to_string(f) + " (file frame " + std::to_string(c.first_frame + f) + ", t = " +
             num(c.rate > 0 ? f / c.rate : 0.0) + " s), " + (c.units.empty() ? "file units" : c.units) + ":\n";
    }
    for (int i = 0; i < c.points; ++i) {
      const auto p = c.point(f, i);
      const std::string& label = c.labels[static_cast<std::size_t>(i)];
      if (json) {
        out += (i ? ", " : "") + jsonString(label) + ": ";
        out += p ? "[" + num((*p)[0]) + ", " + num((*p)[1]) + ", " + num((*p)[2]) + "]" : std::string("null");
      } else {
        char line[256];
        if (p) {
          std::snprintf(line, sizeof line, "  %-16s (%12.4f, %12.4f, %12.4f)\n", label.c_str(), (*p)[0], (*p)[1], (*p)[2]);
        } else {
          std::snprintf(line, sizeof line, "  %-16s invalid\n", label.c_str());
        }
        out += line;
      }
    }
    if (json) out += "}";
  }
  if (json) {
    if (c.truncated) out += ", \"truncated\": true, \"frames_present\": " + std::to_string(c.frames_present);
    out += "}\n";
  } else if (c.truncated) {
    out += "(truncated file: " + std::to_string(c.frames_present) + " whole frames present of " +
           std::to_string(c.framesDeclared()) + " declared)\n";
  }
  std::fputs(out.c_str(), stdout);
  return 0;
}

std::string vec(const Eigen::Vector3d& v) { return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]"; }

int runPlates(const std::string& path, bool json, bool analog) {
  const mc::C3d c = mc::readC3dFile(path);
  const mc::ForcePlates fp = mc::readForcePlates(c);
  const int count = analog ? fp.samples : c.frames_present;
  const double rate = analog ? fp.rate : c.rate;
  auto at = [&](int p, int k) { return analog ? fp.reaction(p, k) : fp.frameReaction(p, k); };
  const std::string length = c.units.empty() ? "file units" : c.units;
  if (!json) {
    std::printf("file:       %s\n", path.c_str());
    std::printf("plates:     %zu; reactions on the subject in the lab frame, force in N, CoP in %s, free moment in N %s\n",
                fp.plates.size(), length.c_str(), length.c_str());
    for (std::size_t p = 0; p < fp.plates.size(); ++p) {
      const mc::ForcePlate& plate = fp.plates[p];
      std::printf("plate %zu:    type %d, channels", p + 1, plate.type);
      for (const int ch : plate.channels) std::printf(" %s", c.analog_labels[static_cast<std::size_t>(ch)].c_str());
      std::printf("\n  centre %s, normal %s, baseline frames %d..%d\n", vec(plate.centre).c_str(), vec(plate.normal()).c_str(),
                  plate.zero_first, plate.zero_last);
      double peak = 0.0, sum = 0.0;
      int loaded = 0;
      for (int k = 0; k < count; ++k) {
        const mc::PlateReaction r = at(static_cast<int>(p), k);
        peak = std::max(peak, r.normal_force);
        if (r.normal_force >= fp.threshold) {
          ++loaded;
          sum += r.normal_force;
        }
      }
      std::printf("  loaded (>= %.0f N) %d of %d %s (%.3f s), mean normal force while loaded %.1f N, peak %.1f N\n",
                  fp.threshold, loaded, count, analog ? "samples" : "frames", rate > 0 ? loaded / rate : 0.0,
                  loaded > 0 ? sum / loaded : 0.0, peak);
    }
    return 0;
  }
  std::string out = "{\"file\": " + jsonString(path) + ", \"per\": " + jsonString(analog ? "analog sample" : "frame") +
                    ", \"rate\": " + num(rate) + ", \"count\": " + std::to_string(count) + ", \"units\": " +
                    jsonString(c.units) + ", \"threshold_n\": " + num(fp.threshold) + ", \"plates\": [";
  for (std::size_t p = 0; p < fp.plates.size(); ++p) {
    const mc::ForcePlate& plate = fp.plates[p];
    out += (p ? ", " : "") + std::string("{\"type\": ") + std::to_string(plate.type) + ", \"channels\": [";
    for (std::size_t q = 0; q < plate.channels.size(); ++q) {
      out += (q ? ", " : "") + jsonString(c.analog_labels[static_cast<std::size_t>(plate.channels[q])]);
    }
    out += "], \"corners\": [";
    for (std::size_t q = 0; q < 4; ++q) out += (q ? ", " : "") + vec(plate.corners[q]);
    out += "], \"origin\": " + vec(plate.origin) + ", \"centre\": " + vec(plate.centre) + ", \"normal\": " +
           vec(plate.normal()) + ", \"force\": [";
    std::string cop = "], \"cop\": [", moment = "], \"free_moment\": [";
    for (int k = 0; k < count; ++k) {
      const mc::PlateReaction r = at(static_cast<int>(p), k);
      const char* sep = k ? ", " : "";
      out += sep + vec(r.force);
      cop += sep + (r.cop.allFinite() ? vec(r.cop) : std::string("null"));
      moment += sep + num(r.free_moment);
    }
    out += cop + moment + "]}";
  }
  out += "]}\n";
  std::fputs(out.c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-c3d: inspect a C3D motion capture (header, parameters, 3D marker positions, force plates).\n"
               "Reads Intel, DEC/VAX and SGI/MIPS files, int16 and float storage, and their analog channels.\n"
               "Exit codes: 0 ok, 2 bad input: unreadable or malformed C3D (message 'FILE: byte OFFSET: what'), "
               "bad command line, frame out of range.",
               "mannequin-c3d"};
  app.require_subcommand(1, 1);

  std::string info_file;
  bool info_json = false;
  CLI::App* info = app.add_subcommand(
      "info",
      "Summary of a C3D file. --json prints one object: {\"points\": N, \"frames\": last-first+1, \"rate\": Hz, "
      "\"first_frame\": N, \"last_frame\": N, \"labels\": [POINT:LABELS trimmed], \"analog_per_frame\": N, "
      "\"processor\": \"intel\"|\"dec\"|\"mips\", \"storage\": \"int16\"|\"float\", \"scale\": POINT:SCALE, "
      "\"units\": POINT:UNITS, \"truncated\": bool, \"frames_present\": whole frames in the file}.");
  info->add_option("FILE", info_file, "C3D file")->required();
  info->add_flag("--json", info_json, "machine-readable output");

  std::string points_file;
  std::string points_frames;
  bool points_json = false;
  CLI::App* points = app.add_subcommand(
      "points",
      "Marker positions at the listed 0-based frames, in the file's units.\n"
      "--json prints {\"<frame>\": {\"<label>\": [x, y, z] or null, ...}, ...}: null where the sample is invalid "
      "(negative residual word). The <frame> key is the RESOLVED 0-based index (-1 on a 450-frame file prints "
      "\"449\"); repeated frames are printed once. A truncated file is read up to its last whole frame (frames "
      "count from the end of those) and the object ends with \"truncated\": true, \"frames_present\": N.");
  points->add_option("FILE", points_file, "C3D file")->required();
  points->add_option("--frames", points_frames,
                     "comma-separated frame indices, negative = from the end (e.g. 0,250,-1)")
      ->required();
  points->add_flag("--json", points_json, "machine-readable output");

  std::string plates_file;
  bool plates_json = false;
  bool plates_analog = false;
  CLI::App* plates = app.add_subcommand(
      "plates",
      "Force plates (FORCE_PLATFORM types 1-4): the ground reaction on the subject in the lab frame, per 3D frame "
      "(the plate's wrench averaged over the frame's analog samples) or per analog sample (--analog). Text: each "
      "plate's type, channels, centre, normal, and its loaded time, mean and peak normal force. --json prints "
      "{\"file\", \"per\": \"frame\"|\"analog sample\", \"rate\": Hz, \"count\": N, \"units\": POINT:UNITS, "
      "\"threshold_n\": 20, \"plates\": [{\"type\", \"channels\": [ANALOG:LABELS], \"corners\", \"origin\", "
      "\"centre\", \"normal\", \"force\": [[fx, fy, fz] N, ...], \"cop\": [[x, y, z] or null below the threshold, ...], "
      "\"free_moment\": [N x length unit, ...]}]}.");
  plates->add_option("FILE", plates_file, "C3D file")->required();
  plates->add_flag("--json", plates_json, "machine-readable output");
  plates->add_flag("--analog", plates_analog, "one value per analog sample instead of per 3D frame");

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
      if (plates->parsed()) return runPlates(plates_file, plates_json, plates_analog);
      return runPoints(points_file, points_frames, points_json);
    } catch (const UsageError& e) {
      std::cerr << "mannequin-c3d: " << e.what() << "\n";
      return kExitBadInput;
    } catch (const mc::C3dError& e) {
      std::cerr << "mannequin-c3d: " << e.what() << "\n";
      return kExitBadInput;
    }
  });
}
