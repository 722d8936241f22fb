#include "mannequin/mocap/force_plate.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mannequin::mocap {

namespace {

using Wrench = Eigen::Matrix<double, 6, 1>;

/// The parameter FORCE_PLATFORM:<name>, or nullptr.
const C3dParameter* param(const C3d& c, const char* name) { return c.find("FORCE_PLATFORM", name); }

[[noreturn]] void fail(const C3d& c, const C3dParameter* p, const std::string& what) {
  throw C3dError(c.file, p != nullptr ? p->offset : 0, what);
}

/// At least `n` finite numbers in FORCE_PLATFORM:<name>, else a C3dError naming it.
const C3dParameter& numbers(const C3d& c, const char* name, std::size_t n, const std::string& why) {
  const C3dParameter* p = param(c, name);
  if (p == nullptr) fail(c, param(c, "USED"), std::string("FORCE_PLATFORM:") + name + " is missing (" + why + ")");
  if (p->numbers.size() < n) {
    fail(c, p, std::string("FORCE_PLATFORM:") + name + " has " + std::to_string(p->numbers.size()) + " values, " +
                   std::to_string(n) + " needed (" + why + ")");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(p->numbers[k])) fail(c, p, std::string("FORCE_PLATFORM:") + name + " value " + std::to_string(k + 1) + " is not finite");
  }
  return *p;
}

/// The surface centre seen from the point the plate's wrench is expressed about (plate frame).
Eigen::Vector3d surfaceFromReference(const ForcePlate& plate) {
  switch (plate.type) {
    case 1:
      return Eigen::Vector3d::Zero();  // type 1 wrenches are built about the surface centre
    case 3:
      return Eigen::Vector3d(0.0, 0.0, plate.origin.z());  // about the centre of the sensor plane
    default:
      return plate.origin;  // types 2 and 4: about the transducer's origin
  }
}

/// The plate's channels (after the baseline) as a wrench about its reference point, plate frame.
Wrench toWrench(const ForcePlate& plate, const double* v) {
  Wrench w;
  switch (plate.type) {
    case 1: {  // Fx Fy Fz, CoP x y (from the surface centre), Tz
      const double fx = v[0], fy = v[1], fz = v[2], px = v[3], py = v[4], tz = v[5];
      w << fx, fy, fz, py * fz, -px * fz, px * fy - py * fx + tz;
      break;
    }
    case 3: {  // Kistler: sensors at (±a, ±b) of the centre
      const double a = plate.origin.x(), b = plate.origin.y();
      const double fx12 = v[0], fx34 = v[1], fy14 = v[2], fy23 = v[3], fz1 = v[4], fz2 = v[5], fz3 = v[6], fz4 = v[7];
      w << fx12 + fx34, fy14 + fy23, fz1 + fz2 + fz3 + fz4, b * (fz1 + fz2 - fz3 - fz4), a * (-fz1 + fz2 + fz3 - fz4),
          b * (-fx12 + fx34) + a * (fy14 - fy23);
      break;
    }
    case 4: {
      Wrench raw;
      for (int k = 0; k < 6; ++k) raw[k] = v[k];
      w = plate.calibration * raw;
      break;
    }
    default:
      for (int k = 0; k < 6; ++k) w[k] = v[k];
  }
  return w;
}

}  // namespace

PlateReaction ForcePlates::reactionOf(int p, const Wrench& w) const {
  const ForcePlate& plate = plates[static_cast<std::size_t>(p)];
  const Eigen::Vector3d f = w.head<3>(), m = w.tail<3>();
  PlateReaction r;
  r.force = plate.axes * f;  // the channels give the reaction on the subject: rotated to the lab frame
  r.normal_force = -f.z();   // along the outward normal, the plate's −z
  if (!(r.normal_force >= threshold)) return r;
  // the wrench's line of action meets the surface (plate z = s.z) at (px, py): M = P × F + Tz ẑ about the reference
  const Eigen::Vector3d s = surfaceFromReference(plate);
  const double px = (s.z() * f.x() - m.y()) / f.z();
  const double py = (m.x() + s.z() * f.y()) / f.z();
  const double tz = m.z() - (px * f.y() - py * f.x());
  r.cop = plate.centre + plate.axes * Eigen::Vector3d(px - s.x(), py - s.y(), 0.0);
  // tz is about the plate's +z (into the plate): about the outward normal it is −tz
  r.free_moment = -tz;
  return r;
}

PlateReaction ForcePlates::reaction(int p, int sample) const {
  if (p < 0 || p >= static_cast<int>(plates.size()) || sample < 0 || sample >= samples) {
    throw std::out_of_range("force plate " + std::to_string(p) + ", analog sample " + std::to_string(sample) + ": the file has " +
                            std::to_string(plates.size()) + " plates and " + std::to_string(samples) + " samples");
  }
  return reactionOf(p, wrenchAt(p, sample));
}

PlateReaction ForcePlates::frameReaction(int p, int frame) const {
  if (p < 0 || p >= static_cast<int>(plates.size()) || frame < 0 || subframes <= 0 || frame >= samples / subframes) {
    throw std::out_of_range("force plate " + std::to_string(p) + ", frame " + std::to_string(frame) + ": the file has " +
                            std::to_string(plates.size()) + " plates and " + std::to_string(subframes > 0 ? samples / subframes : 0) +
                            " frames");
  }
  Wrench mean = Wrench::Zero();
  for (int k = 0; k < subframes; ++k) mean += wrenchAt(p, frame * subframes + k);
  return reactionOf(p, mean / static_cast<double>(subframes));
}

ForcePlates readForcePlates(const C3d& c) {
  ForcePlates out;
  const C3dParameter* used = param(c, "USED");
  if (used == nullptr || used->numbers.empty() || used->numbers.front() == 0.0) return out;
  const double nu = used->numbers.front();
  if (!std::isfinite(nu) || nu < 0.0 || nu != std::floor(nu) || nu > 65535.0) {
    fail(c, used, "FORCE_PLATFORM:USED is not a plate count (" + std::to_string(nu) + ")");
  }
  const auto n = static_cast<std::size_t>(nu);
  if (c.analog_channels <= 0) {
    fail(c, used, "FORCE_PLATFORM:USED = " + std::to_string(n) + " but the file has no analog channels (ANALOG:USED)");
  }
  out.rate = c.analog_rate;
  out.subframes = c.analog_subframes;
  out.samples = c.analogSamples();

  const C3dParameter& type = numbers(c, "TYPE", n, "one per plate");
  const C3dParameter* channel = param(c, "CHANNEL");
  if (channel == nullptr) fail(c, used, "FORCE_PLATFORM:CHANNEL is missing (the analog channels of each plate)");
  const std::size_t rows = channel->dims.empty() ? channel->numbers.size() : static_cast<std::size_t>(channel->dims[0]);
  const C3dParameter& corners = numbers(c, "CORNERS", 12 * n, "4 corners × 3 coordinates per plate");
  // ZERO: a range of 1-based 3D frames for the baseline; 0 0 none; "0 10" means 1..10; a range running past
  // the frames present (a trimmed file) is cut at the last frame (the C3D user guide, FORCE_PLATFORM:ZERO)
  const C3dParameter* zero = param(c, "ZERO");
  int zero_first = 0, zero_last = 0;
  if (zero != nullptr && zero->numbers.size() >= 2) {
    const double z0 = zero->numbers[0], z1 = zero->numbers[1];
    const auto whole = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 2147483647.0 && v == std::floor(v); };
    const std::string range = "FORCE_PLATFORM:ZERO = " + std::to_string(z0) + " " + std::to_string(z1);
    if (!whole(z0) || !whole(z1)) fail(c, zero, range + " is not a range of frame numbers");
    if (z1 > 0.0) {
      zero_first = std::max(1, static_cast<int>(z0));
      zero_last = static_cast<int>(std::min<double>(z1, c.frames_present));
      if (z1 < z0 || zero_first > c.frames_present) {
        fail(c, zero, range + " is not a range inside the file's frames 1.." + std::to_string(c.frames_present) + " (or 0 0)");
      }
    } else if (z0 != 0.0) {
      fail(c, zero, range + ": the last frame is before the first");
    }
  }

  for (std::size_t p = 0; p < n; ++p) {
    ForcePlate plate;
    const std::string which = "plate " + std::to_string(p + 1);
    const double t = type.numbers[p];
    if (t != 1.0 && t != 2.0 && t != 3.0 && t != 4.0) {
      fail(c, &type, "FORCE_PLATFORM:TYPE of " + which + " is " + std::to_string(t) + ": types 1, 2, 3 and 4 are read");
    }
    plate.type = static_cast<int>(t);
    const std::size_t needed = plate.type == 3 ? 8 : 6;
    if (rows < needed || channel->numbers.size() < rows * (p + 1)) {
      fail(c, channel, "FORCE_PLATFORM:CHANNEL gives " + std::to_string(rows) + " channels per plate for " +
                           std::to_string(n) + " plates (" + std::to_string(channel->numbers.size()) + " values); type " +
                           std::to_string(plate.type) + " (" + which + ") needs " + std::to_string(needed));
    }
    for (std::size_t k = 0; k < needed; ++k) {
      const double ch = channel->numbers[p * rows + k];
      if (!(ch >= 1.0 && ch <= c.analog_channels && ch == std::floor(ch))) {
        fail(c, channel, "FORCE_PLATFORM:CHANNEL " + std::to_string(k + 1) + " of " + which + " is " + std::to_string(ch) +
                             ": the file has analog channels 1.." + std::to_string(c.analog_channels));
      }
      plate.channels.push_back(static_cast<int>(ch) - 1);
    }
    for (std::size_t k = 0; k < 4; ++k) {
      for (std::size_t i = 0; i < 3; ++i) plate.corners[k][static_cast<Eigen::Index>(i)] = corners.numbers[p * 12 + k * 3 + i];
    }
    if (plate.type != 1) {
      const C3dParameter& origin = numbers(c, "ORIGIN", 3 * n, "3 coordinates per plate of types 2, 3, 4");
      plate.origin = Eigen::Vector3d(origin.numbers[3 * p], origin.numbers[3 * p + 1], origin.numbers[3 * p + 2]);
      // types 2 and 4: the surface is above the transducer, z < 0 in the plate's z-down frame; some writers
      // store the opposite vector (z > 0), which is turned round, as Visual3D and ezc3d do
      if ((plate.type == 2 || plate.type == 4) && plate.origin.z() > 0.0) plate.origin = -plate.origin;
    }
    if (plate.type == 4) {
      const C3dParameter& cal = numbers(c, "CAL_MATRIX", 36 * n, "a 6 × 6 matrix per plate; type 4 needs it");
      if (cal.dims.size() < 2 || cal.dims[0] != 6 || cal.dims[1] != 6) {
        fail(c, &cal, "FORCE_PLATFORM:CAL_MATRIX is not 6 × 6 per plate");
      }
      // first index fastest, as every C3D array: element (row i, column j) of plate p at i + 6 j + 36 p
      for (int j = 0; j < 6; ++j) {
        for (int i = 0; i < 6; ++i) plate.calibration(i, j) = cal.numbers[36 * p + static_cast<std::size_t>(6 * j + i)];
      }
    }
    // the plate's axes from its corners (1: +x+y, 2: −x+y, 3: −x−y, 4: +x−y)
    const auto& k = plate.corners;
    const Eigen::Vector3d x = (k[0] + k[3]) - (k[1] + k[2]);
    const Eigen::Vector3d y = (k[0] + k[1]) - (k[2] + k[3]);
    const double size = std::max(x.norm(), y.norm());
    if (!(size > 0.0) || x.norm() < 1e-6 * size || y.norm() < 1e-6 * size || x.cross(y).norm() < 1e-3 * x.norm() * y.norm()) {
      fail(c, &corners, "FORCE_PLATFORM:CORNERS of " + which + " do not span a plate");
    }
    // orthonormal axes: x from the corners, z = x × y, y completing the right-handed frame
    const Eigen::Vector3d ex = x.normalized();
    const Eigen::Vector3d ez = x.cross(y).normalized();
    plate.axes.col(0) = ex;
    plate.axes.col(1) = ez.cross(ex);
    plate.axes.col(2) = ez;
    plate.centre = 0.25 * (k[0] + k[1] + k[2] + k[3]);
    plate.zero_first = zero_first;
    plate.zero_last = zero_last;
    // the unloaded baseline: each channel's mean over the ZERO frames
    plate.baseline.assign(needed, 0.0);
    if (zero_first > 0) {
      const int first = (zero_first - 1) * c.analog_subframes, last = zero_last * c.analog_subframes;
      for (std::size_t q = 0; q < needed; ++q) {
        double sum = 0.0;
        for (int s = first; s < last; ++s) sum += c.analog(s, plate.channels[q]);
        plate.baseline[q] = sum / (last - first);
      }
    }
    out.plates.push_back(std::move(plate));
  }

  out.wrench.resize(n * static_cast<std::size_t>(out.samples));
  std::array<double, 8> v{};
  for (std::size_t p = 0; p < n; ++p) {
    const ForcePlate& plate = out.plates[p];
    for (int s = 0; s < out.samples; ++s) {
      for (std::size_t q = 0; q < plate.channels.size(); ++q) v[q] = c.analog(s, plate.channels[q]) - plate.baseline[q];
      out.wrench[p * static_cast<std::size_t>(out.samples) + static_cast<std::size_t>(s)] = toWrench(plate, v.data());
    }
  }
  return out;
}

}  // namespace mannequin::mocap
