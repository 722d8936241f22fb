#include "mannequin/mocap/c3d.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace mannequin::mocap {

namespace {

constexpr std::size_t kBlock = 512;
constexpr std::uint8_t kKey = 0x50;

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string trim(std::string_view s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  auto blank = [](char c) { return c == ' ' || c == '\0' || c == '\t' || c == '\r' || c == '\n'; };
  while (b < e && blank(s[b])) ++b;
  while (e > b && blank(s[e - 1])) --e;
  return std::string(s.substr(b, e - b));
}

/// Bounds-checked access to the file's bytes in the processor's byte order and float format.
class Reader {
 public:
  Reader(std::string_view bytes, const std::string& file) : b_(bytes), file_(file) {}

  [[noreturn]] void fail(std::size_t offset, const std::string& what) const { throw C3dError(file_, offset, what); }

  std::size_t size() const { return b_.size(); }
  void setProcessor(C3dProcessor p) { proc_ = p; }

  /// Throws unless [offset, offset + n) lies inside [0, end).
  void need(std::size_t offset, std::size_t n, std::size_t end, const std::string& what) const {
    if (offset > end || n > end - offset) {
      std::ostringstream s;
      s << what << " runs past the end of the " << (end == b_.size() ? "file" : "parameter section") << " ("
        << n << " bytes needed, " << (offset > end ? 0 : end - offset) << " left)";
      fail(offset, s.str());
    }
  }

  std::uint8_t u8(std::size_t o) const { return static_cast<std::uint8_t>(b_[o]); }
  std::int8_t s8(std::size_t o) const { return static_cast<std::int8_t>(u8(o)); }
  std::uint16_t u16(std::size_t o) const {
    const std::uint16_t lo = u8(o);
    const std::uint16_t hi = u8(o + 1);
    return proc_ == C3dProcessor::kMips ? static_cast<std::uint16_t>((lo << 8) | hi)
                                        : static_cast<std::uint16_t>((hi << 8) | lo);
  }
  std::int16_t s16(std::size_t o) const { return static_cast<std::int16_t>(u16(o)); }
  float f32(std::size_t o) const {
    const std::uint32_t b0 = u8(o), b1 = u8(o + 1), b2 = u8(o + 2), b3 = u8(o + 3);
    switch (proc_) {
      case C3dProcessor::kIntel:
        return std::bit_cast<float>(b0 | (b1 << 8) | (b2 << 16) | (b3 << 24));
      case C3dProcessor::kMips:
        return std::bit_cast<float>(b3 | (b2 << 8) | (b1 << 16) | (b0 << 24));
      case C3dProcessor::kDec:
        break;
    }
    // VAX F_floating: two little-endian 16-bit words, the one holding sign, exponent and the high
    // fraction bits first; value = (0.5 + f / 2^24) * 2^(e - 128), e = 0 is zero (or, with the sign
    // set, the reserved operand: NaN here)
    const std::uint32_t bits = (b1 << 24) | (b0 << 16) | (b3 << 8) | b2;
    const bool negative = (bits >> 31) != 0;
    const int e = static_cast<int>((bits >> 23) & 0xffu);
    const std::uint32_t f = bits & 0x7fffffu;
    if (e == 0) return negative ? std::numeric_limits<float>::quiet_NaN() : 0.0f;
    const double m = 0.5 + static_cast<double>(f) / 16777216.0;
    const double v = std::ldexp(negative ? -m : m, e - 128);
    return static_cast<float>(v);  // the largest VAX magnitude (1.7e38) fits a float
  }

 private:
  std::string_view b_;
  const std::string& file_;
  C3dProcessor proc_ = C3dProcessor::kIntel;
};

/// 16-bit counts the spec stores as int16 but writers use up to 65535. −1 for a value that is not a
/// whole number in [−32768, 65535] (a float parameter holding NaN or 1e30: no conversion of it is defined).
int unsignedCount(double v) {
  if (!std::isfinite(v) || v < -32768.0 || v > 65535.0 || v != std::floor(v)) return -1;
  return v < 0 ? static_cast<int>(v) + 65536 : static_cast<int>(v);
}

}  // namespace

C3dError::C3dError(std::string file, std::size_t offset, const std::string& what)
    : std::runtime_error(file + ": byte " + std::to_string(offset) + ": " + what),
      file_(std::move(file)),
      offset_(offset),
      reason_(what) {}

const char* c3dProcessorName(C3dProcessor p) {
  switch (p) {
    case C3dProcessor::kIntel:
      return "intel";
    case C3dProcessor::kDec:
      return "dec";
    case C3dProcessor::kMips:
      return "mips";
  }
  return "?";
}

const char* c3dStorageName(C3dStorage s) { return s == C3dStorage::kFloat ? "float" : "int16"; }

std::size_t C3dParameter::count() const {
  std::size_t n = 1;
  for (const int d : dims) n *= static_cast<std::size_t>(d);
  return n;
}

std::vector<std::string> C3dParameter::strings() const {
  std::vector<std::string> out;
  if (type != -1) return out;
  if (dims.size() <= 1) {
    out.push_back(trim(chars));
    return out;
  }
  const auto len = static_cast<std::size_t>(dims[0]);
  if (len == 0) return out;
  for (std::size_t at = 0; at + len <= chars.size(); at += len) out.push_back(trim(std::string_view(chars).substr(at, len)));
  return out;
}

const C3dParameter* C3d::find(std::string_view group, std::string_view name) const {
  const std::string g = upper(group);
  const std::string n = upper(name);
  for (const C3dParameter& p : parameters) {
    if (upper(p.group) == g && upper(p.name) == n) return &p;
  }
  return nullptr;
}

std::optional<std::array<double, 3>> C3d::point(int frame, int index) const {
  if (frame < 0 || frame >= frames_present || index < 0 || index >= points) {
    throw std::out_of_range("C3d::point: frame " + std::to_string(frame) + " point " + std::to_string(index) +
                            " outside " + std::to_string(frames_present) + " frames x " + std::to_string(points) +
                            " points");
  }
  const std::size_t k = static_cast<std::size_t>(frame) * static_cast<std::size_t>(points) + static_cast<std::size_t>(index);
  if (!(residual[k] >= 0.0f)) return std::nullopt;
  return std::array<double, 3>{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
}

int C3d::pointIndex(std::string_view label) const {
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == label) return static_cast<int>(i);
  }
  return -1;
}

int resolveC3dFrame(const C3d& c3d, long long frame) {
  const long long n = c3d.frames_present;
  const long long f = frame < 0 ? n + frame : frame;
  if (f < 0 || f >= n) {
    throw std::out_of_range("frame " + std::to_string(frame) + " outside the " + std::to_string(n) +
                            " frames present (0.." + std::to_string(n - 1) + ", or -" + std::to_string(n) +
                            "..-1 from the end)");
  }
  return static_cast<int>(f);
}

C3d parseC3d(std::string_view bytes, const std::string& file) {
  Reader r(bytes, file);
  C3d c;
  c.file = file;

  // --- header block: word 1 = parameter block number, key 0x50
  r.need(0, kBlock, r.size(), "the 512-byte header");
  if (r.u8(1) != kKey) {
    std::ostringstream s;
    s << "bad magic: byte 1 is 0x" << std::hex << int(r.u8(1)) << ", a C3D header has 0x50";
    r.fail(1, s.str());
  }
  const int param_block = r.u8(0);
  if (param_block < 2) r.fail(0, "bad parameter block pointer " + std::to_string(param_block) + " (the parameters start at block 2 or later)");
  const std::size_t param_start = static_cast<std::size_t>(param_block - 1) * kBlock;
  if (param_start + 4 > r.size()) {
    r.fail(0, "bad parameter block pointer " + std::to_string(param_block) + ": the parameter section (byte " +
                  std::to_string(param_start) + ") is past the end of the file (" + std::to_string(r.size()) + " bytes)");
  }
  const int param_blocks = r.u8(param_start + 2);
  const int proc = r.u8(param_start + 3);
  if (proc < 84 || proc > 86) {
    r.fail(param_start + 3, "unknown processor type " + std::to_string(proc) + " (84 Intel, 85 DEC, 86 SGI/MIPS)");
  }
  c.processor = static_cast<C3dProcessor>(proc);
  r.setProcessor(c.processor);
  if (param_blocks == 0) r.fail(param_start + 2, "the parameter section declares 0 blocks");

  // --- header words (1-based word n at byte 2(n-1))
  c.points = r.u16(2);
  c.analog_per_frame = r.u16(4);
  c.first_frame = r.u16(6);
  c.last_frame = r.u16(8);
  double scale = r.f32(12);
  int data_start = r.u16(16);
  double rate = r.f32(20);

  // --- parameter section: a chain of group and parameter records
  const std::size_t end = std::min(r.size(), param_start + static_cast<std::size_t>(param_blocks) * kBlock);
  struct Group {
    int id;
    std::string name;
  };
  std::vector<Group> groups;
  std::vector<int> param_group;
  std::size_t pos = param_start + 4;
  while (pos + 2 <= end) {
    const int nlen = std::abs(static_cast<int>(r.s8(pos)));
    const int id = r.s8(pos + 1);
    if (nlen == 0 || id == 0) break;  // the terminating record
    const std::size_t rec = pos;
    r.need(pos + 2, static_cast<std::size_t>(nlen) + 2, end, "a group/parameter name and its next-record offset");
    std::string name(bytes.substr(pos + 2, static_cast<std::size_t>(nlen)));
    const std::size_t p = pos + 2 + static_cast<std::size_t>(nlen);
    const int next = r.s16(p);
    std::size_t q = p + 2;
    if (id < 0) {
      r.need(q, 1, end, "group " + name + "'s description length");
      const std::size_t dlen = r.u8(q);
      r.need(q + 1, dlen, end, "a group description");
      groups.push_back({-id, upper(trim(name))});
    } else {
      C3dParameter par;
      par.name = trim(name);
      par.offset = rec;
      r.need(q, 2, end, "a parameter's type and dimension count");
      par.type = r.s8(q);
      const int ndims = r.u8(q + 1);
      if (par.type != -1 && par.type != 1 && par.type != 2 && par.type != 4) {
        r.fail(q, "parameter " + par.name + ": bad type " + std::to_string(par.type) + " (-1, 1, 2 or 4)");
      }
      q += 2;
      r.need(q, static_cast<std::size_t>(ndims), end, "a parameter's dimensions");
      std::size_t count = 1;
      const std::size_t elem = static_cast<std::size_t>(std::abs(par.type));
      for (int d = 0; d < ndims; ++d) {
        const int dim = r.u8(q + static_cast<std::size_t>(d));
        par.dims.push_back(dim);
        count *= static_cast<std::size_t>(dim);
        // checked before it can overflow: the data must fit in the section
        if (count > (end - q) / elem) {
          r.fail(q, "parameter " + par.name + ": dimensions give more data than the parameter section holds (" +
                        std::to_string(end - q) + " bytes left)");
        }
      }
      q += static_cast<std::size_t>(ndims);
      const std::size_t nbytes = count * elem;
      r.need(q, nbytes, end, "parameter " + par.name + "'s data");
      if (par.type == -1) {
        par.chars.assign(bytes.substr(q, nbytes));
      } else {
        par.numbers.reserve(count);
        for (std::size_t k = 0; k < count; ++k) {
          const std::size_t o = q + k * elem;
          par.numbers.push_back(par.type == 1 ? double(r.u8(o)) : par.type == 2 ? double(r.s16(o)) : double(r.f32(o)));
        }
      }
      q += nbytes;
      r.need(q, 1, end, "a parameter description length");
      const std::size_t dlen = r.u8(q);
      r.need(q + 1, dlen, end, "a parameter description");
      par.description.assign(bytes.substr(q + 1, dlen));
      c.parameters.push_back(std::move(par));
      param_group.push_back(id);
    }
    if (next == 0) break;  // the last record
    if (next < 0) r.fail(p, "negative next-record offset " + std::to_string(next));
    pos = p + static_cast<std::size_t>(next);
  }
  for (std::size_t k = 0; k < c.parameters.size(); ++k) {
    for (const Group& g : groups) {
      if (g.id == param_group[k]) c.parameters[k].group = g.name;
    }
    if (c.parameters[k].group.empty()) c.parameters[k].group = "GROUP" + std::to_string(param_group[k]);
  }

  // --- POINT parameters override the header
  auto scalar = [&](const char* name) -> std::optional<std::pair<double, std::size_t>> {
    const C3dParameter* p = c.find("POINT", name);
    if (p == nullptr || p->numbers.empty()) return std::nullopt;
    return std::make_pair(p->numbers.front(), p->offset);
  };
  if (const auto used = scalar("USED")) {
    const int n = unsignedCount(used->first);
    if (n < 0) r.fail(used->second, "POINT:USED is not a whole count (" + std::to_string(used->first) + ")");
    if (n != c.points) {
      r.fail(used->second, "POINT:USED = " + std::to_string(n) + " but the header (byte 2) declares " +
                               std::to_string(c.points) + " points");
    }
  }
  if (const auto s = scalar("SCALE")) scale = s->first;
  if (const auto s = scalar("RATE")) rate = s->first;
  if (const auto s = scalar("DATA_START")) {
    data_start = unsignedCount(s->first);
    if (data_start < 0) r.fail(s->second, "POINT:DATA_START is not a whole block number (" + std::to_string(s->first) + ")");
  }
  if (!std::isfinite(scale) || scale == 0.0) r.fail(12, "bad point scale " + std::to_string(scale) + " (header or POINT:SCALE)");
  // an int16 sample (|v| <= 32768) or a residual (<= 255) times the scale must stay a finite float: real files
  // scale by 0.001–10; 1e30 leaves 3.3e34 of FLT_MAX's 3.4e38
  if (std::abs(scale) > 1e30) {
    r.fail(12, "point scale " + std::to_string(scale) + " is too large (header or POINT:SCALE): samples times it overflow a float (|scale| <= 1e30)");
  }
  if (!std::isfinite(rate) || rate < 0.0) r.fail(20, "bad frame rate " + std::to_string(rate) + " (header or POINT:RATE)");
  c.scale = scale;
  c.rate = rate;
  c.storage = scale < 0.0 ? C3dStorage::kFloat : C3dStorage::kInt16;
  if (data_start <= param_block) {
    r.fail(16, "data start block " + std::to_string(data_start) + " is not after the parameter block " +
                   std::to_string(param_block));
  }
  c.data_start_block = data_start;
  if (c.last_frame < c.first_frame - 1) {
    r.fail(8, "last frame " + std::to_string(c.last_frame) + " before first frame " + std::to_string(c.first_frame));
  }

  // labels (LABELS, LABELS2, ... for files with more than 255 points) and units
  for (int k = 1; static_cast<int>(c.labels.size()) < c.points; ++k) {
    const C3dParameter* p = c.find("POINT", k == 1 ? std::string("LABELS") : "LABELS" + std::to_string(k));
    if (p == nullptr) break;
    for (const std::string& s : p->strings()) {
      if (static_cast<int>(c.labels.size()) < c.points) c.labels.push_back(s);
    }
  }
  for (int k = static_cast<int>(c.labels.size()); k < c.points; ++k) c.labels.push_back("P" + std::to_string(k + 1));
  if (const C3dParameter* p = c.find("POINT", "UNITS")) {
    const auto s = p->strings();
    if (!s.empty()) c.units = s.front();
  }

  // --- ANALOG parameters: channels, subframes, rate, labels, units, scaling (C3D user guide, ANALOG group)
  bool analog_unsigned = false;
  if (c.analog_per_frame > 0) {
    if (const C3dParameter* used = c.find("ANALOG", "USED"); used != nullptr && !used->numbers.empty()) {
      const int n = unsignedCount(used->numbers.front());
      if (n <= 0 || c.analog_per_frame % n != 0) {
        r.fail(used->offset, "ANALOG:USED = " + std::to_string(used->numbers.front()) + " does not divide the " +
                                 std::to_string(c.analog_per_frame) + " analog samples per frame of the header (byte 4)");
      }
      c.analog_channels = n;
      c.analog_subframes = c.analog_per_frame / n;
    }
  }
  if (c.analog_channels > 0) {
    const auto channels = static_cast<std::size_t>(c.analog_channels);
    c.analog_rate = c.rate * c.analog_subframes;
    if (const C3dParameter* p = c.find("ANALOG", "RATE"); p != nullptr && !p->numbers.empty()) {
      const double v = p->numbers.front();
      if (!std::isfinite(v) || v <= 0.0) r.fail(p->offset, "ANALOG:RATE is not a positive rate (" + std::to_string(v) + ")");
      c.analog_rate = v;
    }
    for (int k = 1; c.analog_labels.size() < channels; ++k) {
      const C3dParameter* p = c.find("ANALOG", k == 1 ? std::string("LABELS") : "LABELS" + std::to_string(k));
      if (p == nullptr) break;
      for (const std::string& l : p->strings()) {
        if (c.analog_labels.size() < channels) c.analog_labels.push_back(l);
      }
    }
    for (std::size_t k = c.analog_labels.size(); k < channels; ++k) c.analog_labels.push_back("A" + std::to_string(k + 1));
    if (const C3dParameter* p = c.find("ANALOG", "UNITS")) c.analog_units = p->strings();
    c.analog_units.resize(channels);
    // per-channel numbers: SCALE (default 1) and OFFSET (default 0), one per channel at least, finite
    auto perChannel = [&](const char* name, double fallback) {
      std::vector<double> out(channels, fallback);
      const C3dParameter* p = c.find("ANALOG", name);
      if (p == nullptr) return out;
      if (p->numbers.size() < channels) {
        r.fail(p->offset, std::string("ANALOG:") + name + " has " + std::to_string(p->numbers.size()) +
                              " values for " + std::to_string(channels) + " channels (ANALOG:USED)");
      }
      for (std::size_t k = 0; k < channels; ++k) {
        if (!std::isfinite(p->numbers[k])) {
          r.fail(p->offset, std::string("ANALOG:") + name + " of channel " + std::to_string(k + 1) + " is not finite");
        }
        out[k] = p->numbers[k];
      }
      return out;
    };
    if (const C3dParameter* p = c.find("ANALOG", "FORMAT")) {
      const auto f = p->strings();
      analog_unsigned = !f.empty() && upper(f.front()) == "UNSIGNED";
    }
    c.analog_scale = perChannel("SCALE", 1.0);
    c.analog_offset = perChannel("OFFSET", 0.0);
    // unsigned samples have unsigned offsets (the user guide's notes for programmers): 32768 is stored as −32768
    if (analog_unsigned) {
      for (double& o : c.analog_offset) {
        if (o < 0.0) o += 65536.0;
      }
    }
    if (const C3dParameter* p = c.find("ANALOG", "GEN_SCALE"); p != nullptr && !p->numbers.empty()) {
      const double v = p->numbers.front();
      if (!std::isfinite(v) || v == 0.0) r.fail(p->offset, "ANALOG:GEN_SCALE is not a finite non-zero factor (" + std::to_string(v) + ")");
      c.analog_gen_scale = v;
    }
  }

  // --- the frames: (4 × points + analog) words each, int16 or float; whole frames only
  const std::size_t word = c.storage == C3dStorage::kFloat ? 4 : 2;
  const std::size_t frame_bytes = (4 * static_cast<std::size_t>(c.points) + static_cast<std::size_t>(c.analog_per_frame)) * word;
  const std::size_t data_offset = static_cast<std::size_t>(data_start - 1) * kBlock;
  const int declared = c.framesDeclared();
  const std::size_t available = r.size() > data_offset ? r.size() - data_offset : 0;
  if (frame_bytes == 0) {
    c.frames_present = declared;
  } else {
    c.frames_present = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(declared), available / frame_bytes));
  }
  c.truncated = c.frames_present < declared;
  // sized by the whole frames the file holds, never by a declared count alone
  const std::size_t samples = static_cast<std::size_t>(c.frames_present) * static_cast<std::size_t>(c.points);
  c.xyz.assign(3 * samples, std::numeric_limits<float>::quiet_NaN());
  c.residual.assign(samples, -1.0f);
  const float abs_scale = static_cast<float>(std::abs(scale));
  for (int f = 0; f < c.frames_present; ++f) {
    const std::size_t frame_at = data_offset + static_cast<std::size_t>(f) * frame_bytes;
    for (int i = 0; i < c.points; ++i) {
      const std::size_t o = frame_at + static_cast<std::size_t>(i) * 4 * word;
      const std::size_t k = static_cast<std::size_t>(f) * static_cast<std::size_t>(c.points) + static_cast<std::size_t>(i);
      float x = 0, y = 0, z = 0, res = -1.0f;
      if (c.storage == C3dStorage::kInt16) {
        const std::int16_t w = r.s16(o + 6);
        x = static_cast<float>(r.s16(o) * scale);
        y = static_cast<float>(r.s16(o + 2) * scale);
        z = static_cast<float>(r.s16(o + 4) * scale);
        if (w >= 0) res = static_cast<float>(w & 0xff) * abs_scale;
      } else {
        x = r.f32(o);
        y = r.f32(o + 4);
        z = r.f32(o + 8);
        const float w = r.f32(o + 12);
        // the fourth word holds the int16 residual word (camera mask << 8 | residual / scale) as a float
        if (w >= 0.0f && std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
          res = w < 65536.0f ? static_cast<float>(static_cast<int>(w) & 0xff) * abs_scale : 0.0f;
        }
      }
      if (res >= 0.0f) {
        c.xyz[3 * k] = x;
        c.xyz[3 * k + 1] = y;
        c.xyz[3 * k + 2] = z;
        c.residual[k] = res;
      }
    }
  }
  // the analog words follow the points in each frame (read only when ANALOG:USED says how to split them)
  if (c.analog_channels > 0) {
    const auto per_frame = static_cast<std::size_t>(c.analog_per_frame);
    c.analog_stored.resize(static_cast<std::size_t>(c.frames_present) * per_frame);
    for (int f = 0; f < c.frames_present; ++f) {
      const std::size_t at = data_offset + static_cast<std::size_t>(f) * frame_bytes + 4 * static_cast<std::size_t>(c.points) * word;
      float* out = c.analog_stored.data() + static_cast<std::size_t>(f) * per_frame;
      for (std::size_t k = 0; k < per_frame; ++k) {
        const std::size_t o = at + k * word;
        if (c.storage == C3dStorage::kFloat) {
          out[k] = r.f32(o);
        } else {
          out[k] = analog_unsigned ? static_cast<float>(r.u16(o)) : static_cast<float>(r.s16(o));
        }
      }
    }
  }
  return c;
}

double C3d::analog(int sample, int channel) const {
  const std::size_t k = static_cast<std::size_t>(sample) * static_cast<std::size_t>(analog_channels) + static_cast<std::size_t>(channel);
  const auto ch = static_cast<std::size_t>(channel);
  return (static_cast<double>(analog_stored[k]) - analog_offset[ch]) * analog_scale[ch] * analog_gen_scale;
}

int C3d::analogIndex(std::string_view label) const {
  for (std::size_t k = 0; k < analog_labels.size(); ++k) {
    if (analog_labels[k] == label) return static_cast<int>(k);
  }
  return -1;
}

C3d readC3dFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw C3dError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw C3dError(path, 0, "read error");
  return parseC3d(s.str(), path);
}

}  // namespace mannequin::mocap
