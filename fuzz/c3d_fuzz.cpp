// libFuzzer target for the C3D reader: any input either throws C3dError naming a byte inside it, or
// yields a consistent C3d (whole frames only, finite valid samples, one label per point, analog samples
// matching the channels); its force plates then decode or throw C3dError naming a byte inside it.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mannequin/mocap/c3d.hpp"
#include "mannequin/mocap/force_plate.hpp"

namespace mc = mannequin::mocap;

namespace {

// aborts (a libFuzzer crash) when an invariant of an accepted file is broken
void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  mc::C3d c;
  try {
    c = mc::parseC3d(bytes, "fuzz.c3d");
  } catch (const mc::C3dError& e) {
    check(e.file() == "fuzz.c3d" && e.offset() <= size);
    return 0;
  }
  check(c.points >= 0 && c.points <= 65535 && c.analog_per_frame >= 0);
  check(c.frames_present >= 0 && c.frames_present <= std::max(0, c.framesDeclared()));
  check(c.truncated == (c.frames_present < c.framesDeclared()));
  check(c.labels.size() == static_cast<std::size_t>(c.points));
  const std::size_t samples = static_cast<std::size_t>(c.frames_present) * static_cast<std::size_t>(c.points);
  check(c.xyz.size() == 3 * samples && c.residual.size() == samples);
  // the samples held come from the input: never more bytes than it has
  if (c.points > 0) check(samples * 8 <= size);
  check(std::isfinite(c.rate) && c.rate >= 0.0 && std::isfinite(c.scale) && c.scale != 0.0);
  for (int f = 0; f < c.frames_present; ++f) {
    for (int i = 0; i < c.points; ++i) {
      if (const auto p = c.point(f, i)) {
        for (const double v : *p) check(std::isfinite(v));
      }
    }
  }
  for (const mc::C3dParameter& p : c.parameters) {
    check(p.type == -1 ? p.chars.size() == p.count() : p.numbers.size() == p.count());
    (void)p.strings();
  }
  if (c.frames_present > 0) (void)mc::resolveC3dFrame(c, -1);
  if (c.analog_channels > 0) {
    check(c.analog_subframes * c.analog_channels == c.analog_per_frame);
    check(c.analog_stored.size() == static_cast<std::size_t>(c.frames_present) * static_cast<std::size_t>(c.analog_per_frame));
    check(c.analog_labels.size() == static_cast<std::size_t>(c.analog_channels));
    check(std::isfinite(c.analog_rate) && c.analog_rate >= 0.0);
  } else {
    check(c.analog_stored.empty());
  }
  try {
    const mc::ForcePlates fp = mc::readForcePlates(c);
    check(fp.wrench.size() == fp.plates.size() * static_cast<std::size_t>(fp.samples));
    for (std::size_t p = 0; p < fp.plates.size(); ++p) {
      for (int k = 0; k < fp.samples; k += std::max(1, fp.samples / 16)) (void)fp.reaction(static_cast<int>(p), k);
    }
  } catch (const mc::C3dError& e) {
    check(e.file() == "fuzz.c3d" && e.offset() <= size);
  }
  return 0;
}
