#pragma once
// A test-only C3D writer: int16 or float storage in the three processor formats, from marker data
// (e.g. a parsed real file), so the reader can be checked on formats the shipped samples lack.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "mannequin/mocap/c3d.hpp"

namespace c3dtest {

namespace mc = mannequin::mocap;

struct Marker {
  float x = 0, y = 0, z = 0;
  bool valid = true;
  float residual = 0;  // file units
};

struct WriteSpec {
  mc::C3dProcessor processor = mc::C3dProcessor::kIntel;
  bool float_storage = false;
  double scale = 0.1;  // > 0; written negated for float storage
  double rate = 50.0;
  int first_frame = 1;
  int analog_per_frame = 6;  // words of filler after the points of each frame (must be skipped)
  std::string units = "mm";
  std::vector<std::string> labels;
  std::vector<std::vector<Marker>> frames;  // frames × points
};

class Bytes {
 public:
  explicit Bytes(mc::C3dProcessor p) : p_(p) {}
  std::string s;
  void u8(int v) { s.push_back(static_cast<char>(static_cast<std::uint8_t>(v))); }
  void i16(int v) {
    const auto w = static_cast<std::uint16_t>(v);
    if (p_ == mc::C3dProcessor::kMips) {
      u8(w >> 8);
      u8(w & 0xff);
    } else {
      u8(w & 0xff);
      u8(w >> 8);
    }
  }
  void f32(double v) {
    if (p_ == mc::C3dProcessor::kDec) {
      // VAX F: the IEEE bits of 4v, 16-bit words swapped (normal numbers; 0 is all zero bits)
      const std::uint32_t b = v == 0.0 ? 0u : std::bit_cast<std::uint32_t>(static_cast<float>(4.0 * v));
      u8((b >> 16) & 0xff);
      u8((b >> 24) & 0xff);
      u8(b & 0xff);
      u8((b >> 8) & 0xff);
      return;
    }
    const std::uint32_t b = std::bit_cast<std::uint32_t>(static_cast<float>(v));
    if (p_ == mc::C3dProcessor::kMips) {
      for (int k = 3; k >= 0; --k) u8(static_cast<int>((b >> (8 * k)) & 0xff));
    } else {
      for (int k = 0; k < 4; ++k) u8(static_cast<int>((b >> (8 * k)) & 0xff));
    }
  }
  void str(const std::string& t) { s += t; }
  void padTo(std::size_t n) { s.resize(n, '\0'); }

 private:
  mc::C3dProcessor p_;
};

// one parameter record: type -1 char, 2 int16, 4 float; `last` writes a 0 next-record offset
inline void param(Bytes& b, int group, const std::string& name, int type, const std::vector<int>& dims,
                  const std::vector<double>& numbers, const std::string& chars, bool last = false) {
  b.u8(static_cast<int>(name.size()));
  b.u8(group);
  b.str(name);
  std::size_t data = 0;
  if (type == -1) {
    data = chars.size();
  } else {
    data = numbers.size() * static_cast<std::size_t>(type);
  }
  const std::string desc = "test";
  b.i16(last ? 0 : static_cast<int>(2 + 2 + dims.size() + data + 1 + desc.size()));
  b.u8(type);
  b.u8(static_cast<int>(dims.size()));
  for (const int d : dims) b.u8(d);
  if (type == -1) {
    b.str(chars);
  } else {
    for (const double v : numbers) {
      if (type == 2) {
        b.i16(static_cast<int>(v));
      } else {
        b.f32(v);
      }
    }
  }
  b.u8(static_cast<int>(desc.size()));
  b.str(desc);
}

inline std::string writeC3d(const WriteSpec& w) {
  const int points = static_cast<int>(w.labels.size());
  const int nframes = static_cast<int>(w.frames.size());
  const int last = w.first_frame + nframes - 1;
  const double scale = w.float_storage ? -w.scale : w.scale;
  const int param_blocks = 2;
  const int data_start = 2 + param_blocks;  // blocks 1 header, 2-3 parameters, 4... data
  Bytes b(w.processor);
  // header
  b.u8(2);
  b.u8(0x50);
  b.i16(points);
  b.i16(w.analog_per_frame);
  b.i16(w.first_frame);
  b.i16(last);
  b.i16(10);
  b.f32(scale);
  b.i16(data_start);
  b.i16(w.analog_per_frame);  // analog samples per frame (1 channel)
  b.f32(w.rate);
  b.padTo(512);
  // parameters
  b.u8(1);
  b.u8(0x50);
  b.u8(param_blocks);
  b.u8(static_cast<int>(w.processor));
  const std::string group = "POINT";
  b.u8(static_cast<int>(group.size()));
  b.u8(-1);
  b.str(group);
  b.i16(2 + 1 + 4);
  b.u8(4);
  b.str("test");
  param(b, 1, "USED", 2, {}, {double(points)}, "");
  param(b, 1, "SCALE", 4, {}, {scale}, "");
  param(b, 1, "RATE", 4, {}, {w.rate}, "");
  param(b, 1, "DATA_START", 2, {}, {double(data_start)}, "");
  param(b, 1, "FRAMES", 2, {}, {double(nframes)}, "");
  std::string units = w.units;
  param(b, 1, "UNITS", -1, {static_cast<int>(units.size())}, {}, units);
  std::string labels;
  for (const std::string& l : w.labels) labels += (l + "    ").substr(0, 4);
  param(b, 1, "LABELS", -1, {4, points}, {}, labels, true);
  b.u8(0);
  b.u8(0);
  b.padTo(static_cast<std::size_t>(data_start - 1) * 512);
  // frames
  for (const auto& frame : w.frames) {
    for (const Marker& m : frame) {
      if (w.float_storage) {
        b.f32(m.valid ? m.x : 0.0);
        b.f32(m.valid ? m.y : 0.0);
        b.f32(m.valid ? m.z : 0.0);
        b.f32(m.valid ? double((0x3e << 8) | std::min(255, static_cast<int>(std::lround(m.residual / w.scale)))) : -1.0);
      } else {
        b.i16(m.valid ? static_cast<int>(std::lround(m.x / w.scale)) : 0);
        b.i16(m.valid ? static_cast<int>(std::lround(m.y / w.scale)) : 0);
        b.i16(m.valid ? static_cast<int>(std::lround(m.z / w.scale)) : 0);
        b.i16(m.valid ? (0x3e << 8) | std::min(255, static_cast<int>(std::lround(m.residual / w.scale))) : -1);
      }
    }
    for (int a = 0; a < w.analog_per_frame; ++a) {
      if (w.float_storage) {
        b.f32(-12345.0);
      } else {
        b.i16(-12345);
      }
    }
  }
  b.padTo((b.s.size() + 511) / 512 * 512);
  return b.s;
}

// the markers of a parsed file, as the writer takes them
inline WriteSpec specFrom(const mc::C3d& c) {
  WriteSpec w;
  w.labels = c.labels;
  w.rate = c.rate;
  w.units = c.units;
  w.first_frame = c.first_frame;
  for (int f = 0; f < c.frames_present; ++f) {
    std::vector<Marker> frame;
    for (int i = 0; i < c.points; ++i) {
      const auto p = c.point(f, i);
      const std::size_t k = static_cast<std::size_t>(f) * static_cast<std::size_t>(c.points) + static_cast<std::size_t>(i);
      Marker m;
      if (p) {
        m.x = static_cast<float>((*p)[0]);
        m.y = static_cast<float>((*p)[1]);
        m.z = static_cast<float>((*p)[2]);
        m.residual = c.residual[k];
      } else {
        m.valid = false;
      }
      frame.push_back(m);
    }
    w.frames.push_back(frame);
  }
  return w;
}

}  // namespace c3dtest
