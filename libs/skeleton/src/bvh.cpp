/// \file bvh.cpp
/// \brief BVH reader (hand-written lexer, no recursion) and forward kinematics.
#include "mannequin/skeleton/bvh.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <unordered_map>

namespace mannequin::skeleton {

namespace {

std::string formatError(const std::string& file, int line, const std::string& message) {
  if (line > 0) return file + ":" + std::to_string(line) + ": " + message;
  return file + ": " + message;
}

}  // namespace

BvhError::BvhError(std::string file, int line, const std::string& message)
    : std::runtime_error(formatError(file, line, message)), file_(std::move(file)), line_(line), message_(message) {}

std::string_view bvhChannelName(BvhChannel channel) {
  switch (channel) {
    case BvhChannel::Xposition: return "Xposition";
    case BvhChannel::Yposition: return "Yposition";
    case BvhChannel::Zposition: return "Zposition";
    case BvhChannel::Xrotation: return "Xrotation";
    case BvhChannel::Yrotation: return "Yrotation";
    case BvhChannel::Zrotation: return "Zrotation";
  }
  return "?";
}

double bvhUnitScale(BvhUnit unit) {
  switch (unit) {
    case BvhUnit::Metre: return 1.0;
    case BvhUnit::Centimetre: return 0.01;
    case BvhUnit::Inch: return 0.0254;
    case BvhUnit::Cmu: return 0.056444;
  }
  return 1.0;
}

namespace {

constexpr int kMaxChannelsPerJoint = 6;

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
bool isSpace(char c) { return isBlank(c) || c == '\r' || c == '\n'; }

/// A token of the input: its text (empty at end of input) and 1-based line.
struct Token {
  std::string_view text;
  int line = 0;
};

/// Error text for a token: 'TEXT' (shortened, control bytes escaped) or "end of file".
std::string quote(std::string_view text) {
  if (text.empty()) return "end of file";
  std::string out = "'";
  const std::size_t shown = std::min<std::size_t>(text.size(), 40);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (shown < text.size()) out += "...";
  return out + "'";
}

/// Parses a whole token as a finite double ("1", "-.5", "+2e-3"); false if it is not one.
enum class NumberStatus { Ok, NotANumber, NotFinite };
NumberStatus parseDouble(std::string_view text, double& value) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  // from_chars rejects a leading '+', which some writers emit
  if (first != last && *first == '+' && last - first > 1 && first[1] != '-' && first[1] != '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range) {
    return NumberStatus::NotFinite;
  }
  if (ec != std::errc() || ptr != last) return NumberStatus::NotANumber;
  if (!std::isfinite(value)) return NumberStatus::NotFinite;
  return NumberStatus::Ok;
}

/// Lexer over the whole text. Line ends: LF, CRLF or a lone CR. Braces are tokens of their own.
class Lexer {
 public:
  Lexer(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  [[noreturn]] void fail(int line, const std::string& message) const { throw BvhError(source_, line, message); }

  int line() const { return line_; }
  bool atEnd() const { return pos_ >= text_.size(); }
  std::size_t remaining() const { return text_.size() - pos_; }

  // next token, skipping any whitespace including line ends; empty text at end of input
  Token next() {
    skipSpace();
    Token t{{}, line_};
    if (atEnd()) return t;
    const std::size_t start = pos_;
    if (text_[pos_] == '{' || text_[pos_] == '}') {
      ++pos_;
    } else {
      while (!atEnd() && !isSpace(text_[pos_]) && text_[pos_] != '{' && text_[pos_] != '}') ++pos_;
    }
    t.text = text_.substr(start, pos_ - start);
    return t;
  }

  // the rest of the current line up to a '{' or the line end, trimmed (a joint name)
  std::string_view restOfLine() {
    while (!atEnd() && isBlank(text_[pos_])) ++pos_;
    const std::size_t start = pos_;
    while (!atEnd() && text_[pos_] != '\n' && text_[pos_] != '\r' && text_[pos_] != '{') ++pos_;
    std::size_t end = pos_;
    while (end > start && isBlank(text_[end - 1])) --end;
    return text_.substr(start, end - start);
  }

  // skips blanks; true (and consumes the line end) if the current line has nothing more
  bool endOfLine() {
    while (!atEnd() && isBlank(text_[pos_])) ++pos_;
    if (atEnd()) return true;
    if (text_[pos_] == '\n' || text_[pos_] == '\r') {
      consumeLineEnd();
      return true;
    }
    return false;
  }

  // the next token of the current line (blanks skipped); empty if the line has no more
  std::string_view wordOnLine() {
    while (!atEnd() && isBlank(text_[pos_])) ++pos_;
    const std::size_t start = pos_;
    while (!atEnd() && !isSpace(text_[pos_])) ++pos_;
    return text_.substr(start, pos_ - start);
  }

 private:
  void consumeLineEnd() {
    if (text_[pos_] == '\r') {
      ++pos_;
      if (!atEnd() && text_[pos_] == '\n') ++pos_;
    } else {
      ++pos_;
    }
    ++line_;
  }
  void skipSpace() {
    while (!atEnd() && isSpace(text_[pos_])) {
      if (text_[pos_] == '\n' || text_[pos_] == '\r') {
        consumeLineEnd();
      } else {
        ++pos_;
      }
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

/// Case-insensitive comparison of ASCII words.
bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
           return lower(x) == lower(y);
         });
}

bool parseChannel(std::string_view text, BvhChannel& channel) {
  static constexpr std::array<BvhChannel, 6> kAll = {BvhChannel::Xposition, BvhChannel::Yposition,
                                                     BvhChannel::Zposition, BvhChannel::Xrotation,
                                                     BvhChannel::Yrotation, BvhChannel::Zrotation};
  for (const BvhChannel c : kAll) {
    if (equalsIgnoreCase(text, bvhChannelName(c))) {
      channel = c;
      return true;
    }
  }
  return false;
}

/// The recursive-descent grammar of BVH, written as a loop with an explicit stack so that
/// deeply nested input cannot overflow the call stack.
class Parser {
 public:
  Parser(std::string_view text, const std::string& source) : lex_(text, source) {}

  Bvh parse(const BvhReadOptions& options) {
    bvh_.unit_scale_to_m = options.unit_scale_to_m;
    parseHierarchy();
    parseMotion();
    return std::move(bvh_);
  }

 private:
  void expectWord(std::string_view word) {
    const Token t = lex_.next();
    if (t.text != word) lex_.fail(t.line, "expected '" + std::string(word) + "', got " + quote(t.text));
  }

  double expectNumber(const char* what) {
    const Token t = lex_.next();
    double value = 0.0;
    switch (parseDouble(t.text, value)) {
      case NumberStatus::Ok: return value;
      case NumberStatus::NotFinite:
        lex_.fail(t.line, std::string("expected a finite number (") + what + "), got " + quote(t.text));
      case NumberStatus::NotANumber: break;
    }
    lex_.fail(t.line, std::string("expected a number (") + what + "), got " + quote(t.text));
  }

  long long expectInteger(const Token& t, const char* what, long long lo, long long hi) {
    long long value = 0;
    const char* last = t.text.data() + t.text.size();
    const auto [ptr, ec] = std::from_chars(t.text.data(), last, value);
    if (t.text.empty() || ec != std::errc() || ptr != last || value < lo || value > hi) {
      lex_.fail(t.line, std::string("expected ") + what + ", got " + quote(t.text));
    }
    return value;
  }

  // reads "{ OFFSET x y z [CHANNELS n names...]" of a joint whose keyword was on `line`
  void openJoint(std::string name, bool end_site, int line) {
    BvhJoint joint;
    joint.name = std::move(name);
    joint.parent = stack_.empty() ? -1 : stack_.back();
    joint.end_site = end_site;
    joint.line = line;
    joint.first_channel = bvh_.num_channels;
    expectWord("{");
    expectWord("OFFSET");
    for (int k = 0; k < 3; ++k) joint.offset[k] = expectNumber("OFFSET coordinate");
    if (!end_site) {
      expectWord("CHANNELS");
      const Token n = lex_.next();
      const auto count = expectInteger(n, "a channel count from 0 to 6", 0, kMaxChannelsPerJoint);
      for (long long c = 0; c < count; ++c) {
        const Token t = lex_.next();
        BvhChannel channel{};
        if (!parseChannel(t.text, channel)) {
          lex_.fail(t.line, "expected a channel name (Xposition, Yposition, Zposition, Xrotation, Yrotation, "
                            "Zrotation), got " + quote(t.text));
        }
        joint.channels.push_back(channel);
      }
      bvh_.num_channels += static_cast<int>(count);
    }
    stack_.push_back(static_cast<int>(bvh_.joints.size()));
    bvh_.joints.push_back(std::move(joint));
  }

  // a ROOT/JOINT name: the rest of its line, unique in the file
  std::string jointName(const Token& keyword) {
    const std::string_view name = lex_.restOfLine();
    if (name.empty()) {
      lex_.fail(keyword.line, "expected a joint name after " + quote(keyword.text) + ", got " +
                                  (lex_.atEnd() ? std::string("end of file") : std::string("end of line")));
    }
    const auto [it, inserted] = names_.emplace(std::string(name), keyword.line);
    if (!inserted) {
      lex_.fail(keyword.line, "expected a unique joint name, got " + quote(name) + " (already defined at line " +
                                  std::to_string(it->second) + ")");
    }
    return std::string(name);
  }

  void parseHierarchy() {
    expectWord("HIERARCHY");
    const Token root = lex_.next();
    if (root.text != "ROOT") lex_.fail(root.line, "expected 'ROOT', got " + quote(root.text));
    openJoint(jointName(root), false, root.line);
    // body of the innermost open joint: children, then its closing brace
    while (!stack_.empty()) {
      const Token t = lex_.next();
      const bool in_end_site = bvh_.joints[static_cast<std::size_t>(stack_.back())].end_site;
      if (t.text == "}") {
        stack_.pop_back();
      } else if (!in_end_site && t.text == "JOINT") {
        openJoint(jointName(t), false, t.line);
      } else if (!in_end_site && t.text == "End") {
        expectWord("Site");
        openJoint(std::string(), true, t.line);
      } else if (in_end_site) {
        lex_.fail(t.line, "expected '}' closing the End Site, got " + quote(t.text));
      } else {
        lex_.fail(t.line, "expected 'JOINT', 'End Site' or '}', got " + quote(t.text));
      }
    }
  }

  void parseMotion() {
    expectWord("MOTION");
    // "Frames: N" (also "Frames:N")
    Token t = lex_.next();
    const int frames_line = t.line;
    if (t.text.substr(0, 7) != "Frames:") lex_.fail(t.line, "expected 'Frames:', got " + quote(t.text));
    Token n{t.text.substr(7), t.line};
    if (n.text.empty()) n = lex_.next();
    bvh_.num_frames = static_cast<int>(expectInteger(n, "a frame count >= 0", 0, INT_MAX));
    // "Frame Time: dt" (also "Time:dt")
    expectWord("Frame");
    t = lex_.next();
    if (t.text.substr(0, 5) != "Time:") lex_.fail(t.line, "expected 'Time:', got " + quote(t.text));
    Token dt{t.text.substr(5), t.line};
    if (dt.text.empty()) dt = lex_.next();
    double frame_time = 0.0;
    if (parseDouble(dt.text, frame_time) != NumberStatus::Ok || !(frame_time > 0.0)) {
      lex_.fail(dt.line, "expected a frame time > 0 (seconds), got " + quote(dt.text));
    }
    bvh_.frame_time = frame_time;
    if (!lex_.endOfLine()) {
      const int line = lex_.line();
      lex_.fail(line, "expected end of line after the frame time, got " + quote(lex_.wordOnLine()));
    }
    parseFrames(frames_line);
  }

  void parseFrames(int frames_line) {
    const auto nch = static_cast<std::size_t>(bvh_.num_channels);
    const auto nframes = static_cast<std::size_t>(bvh_.num_frames);
    if (nch > 0) {
      // reserve no more than the text can hold (each value takes >= 2 bytes), whatever the header says
      bvh_.motion.reserve(std::min(nframes * nch, lex_.remaining() / 2 + nch));
    }
    std::size_t frame = 0;
    while (nch > 0 && frame < nframes) {
      // blank lines between frames are skipped
      if (lex_.endOfLine()) {
        if (lex_.atEnd()) {
          lex_.fail(lex_.line(), "expected " + std::to_string(nframes) + " frames (declared at line " +
                                     std::to_string(frames_line) + "), found " + std::to_string(frame) +
                                     ": unexpected end of file");
        }
        continue;
      }
      const int line = lex_.line();
      std::size_t count = 0;
      while (!lex_.endOfLine()) {
        const std::string_view word = lex_.wordOnLine();
        ++count;
        if (count > nch) continue;  // counted, reported below
        double value = 0.0;
        switch (parseDouble(word, value)) {
          case NumberStatus::Ok: break;
          case NumberStatus::NotFinite:
            lex_.fail(line, "expected a finite number (channel " + std::to_string(count) + " of frame " +
                                std::to_string(frame) + "), got " + quote(word));
          case NumberStatus::NotANumber:
            lex_.fail(line, "expected a number (channel " + std::to_string(count) + " of frame " +
                                std::to_string(frame) + "), got " + quote(word));
        }
        bvh_.motion.push_back(value);
      }
      if (count != nch) {
        lex_.fail(line, "expected " + std::to_string(nch) + " channel values in frame " + std::to_string(frame) +
                            ", got " + std::to_string(count));
      }
      ++frame;
    }
    // nothing but whitespace may follow the last frame
    const Token extra = lex_.next();
    if (!extra.text.empty()) {
      lex_.fail(extra.line, "expected end of file after " + std::to_string(nframes) + " frames (declared at line " +
                                std::to_string(frames_line) + "), got " + quote(extra.text));
    }
  }

  Lexer lex_;
  Bvh bvh_;
  std::vector<int> stack_;                            // open joints, innermost last
  std::unordered_map<std::string, int> names_;        // joint name -> line of definition
};

/// sin and cos of an angle in degrees, exact at multiples of 90°.
void sinCosDeg(double deg, double& s, double& c) {
  const double q = deg / 90.0;
  if (q == std::floor(q) && std::abs(q) < 1e15) {
    static constexpr double kSin[4] = {0.0, 1.0, 0.0, -1.0};
    static constexpr double kCos[4] = {1.0, 0.0, -1.0, 0.0};
    const auto k = static_cast<std::size_t>(((static_cast<long long>(q) % 4) + 4) % 4);
    s = kSin[k];
    c = kCos[k];
    return;
  }
  const double r = deg * (std::numbers::pi / 180.0);
  s = std::sin(r);
  c = std::cos(r);
}

}  // namespace

Bvh parseBvh(std::string_view text, const std::string& source, const BvhReadOptions& options) {
  if (!std::isfinite(options.unit_scale_to_m) || !(options.unit_scale_to_m > 0.0)) {
    throw std::invalid_argument("parseBvh: unit_scale_to_m must be finite and > 0");
  }
  // a UTF-8 byte-order mark is ignored
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  Parser parser(text, source);
  Bvh bvh = parser.parse(options);
  bvh.source = source;
  return bvh;
}

Bvh readBvhFile(const std::string& path, const BvhReadOptions& options) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw BvhError(path, 0, "cannot open file");
  // one read of the whole file
  const std::streamoff size = in.tellg();
  std::string text;
  if (size > 0) {
    text.resize(static_cast<std::size_t>(size));
    in.seekg(0);
    in.read(text.data(), size);
    if (in.gcount() != size) throw BvhError(path, 0, "cannot read file");
  } else {
    // not seekable (a pipe): read as a stream
    in.clear();
    in.seekg(0);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();
  }
  return parseBvh(text, path, options);
}

int bvhJointCount(const Bvh& bvh) {
  return static_cast<int>(std::count_if(bvh.joints.begin(), bvh.joints.end(),
                                        [](const BvhJoint& j) { return !j.end_site; }));
}

int findBvhJoint(const Bvh& bvh, std::string_view name) {
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    if (!bvh.joints[j].end_site && bvh.joints[j].name == name) return static_cast<int>(j);
  }
  return -1;
}

int resolveBvhFrame(const Bvh& bvh, long long frame) {
  const long long n = bvh.num_frames;
  const long long resolved = frame < 0 ? n + frame : frame;
  if (resolved < 0 || resolved >= n) {
    throw std::out_of_range("frame " + std::to_string(frame) + " is out of range (the motion has " +
                            std::to_string(n) + " frames: 0.." + std::to_string(n - 1) + " or -" +
                            std::to_string(n) + "..-1)");
  }
  return static_cast<int>(resolved);
}

std::span<const double> bvhFrame(const Bvh& bvh, int frame) {
  const auto nch = static_cast<std::size_t>(bvh.num_channels);
  if (nch == 0) return {};
  return std::span<const double>(bvh.motion).subspan(static_cast<std::size_t>(frame) * nch, nch);
}

math::Matrix3 bvhAxisRotation(int axis, double angle_deg) {
  double s = 0.0;
  double c = 1.0;
  sinCosDeg(angle_deg, s, c);
  math::Matrix3 R;
  switch (axis) {
    case 0: R << 1, 0, 0, 0, c, -s, 0, s, c; break;
    case 1: R << c, 0, s, 0, 1, 0, -s, 0, c; break;
    default: R << c, -s, 0, s, c, 0, 0, 0, 1; break;
  }
  return R;
}

namespace {

/// R ← R · R_axis(angle_deg), touching only the two columns the elementary rotation mixes.
void rotateColumns(math::Matrix3& R, int axis, double angle_deg) {
  double s = 0.0;
  double c = 1.0;
  sinCosDeg(angle_deg, s, c);
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  const math::Vector3 ci = R.col(i);
  const math::Vector3 cj = R.col(j);
  R.col(i) = c * ci + s * cj;
  R.col(j) = c * cj - s * ci;
}

}  // namespace

math::SE3 bvhLocalPose(const Bvh& bvh, int joint, std::span<const double> frame, double length_scale) {
  const BvhJoint& j = bvh.joints[static_cast<std::size_t>(joint)];
  math::SE3 pose;
  math::Vector3 t = j.offset;
  // channels in listed order: positions add to the offset, rotations right-multiply
  for (std::size_t c = 0; c < j.channels.size(); ++c) {
    const double v = frame[static_cast<std::size_t>(j.first_channel) + c];
    switch (j.channels[c]) {
      case BvhChannel::Xposition: t.x() += v; break;
      case BvhChannel::Yposition: t.y() += v; break;
      case BvhChannel::Zposition: t.z() += v; break;
      case BvhChannel::Xrotation: rotateColumns(pose.R, 0, v); break;
      case BvhChannel::Yrotation: rotateColumns(pose.R, 1, v); break;
      case BvhChannel::Zrotation: rotateColumns(pose.R, 2, v); break;
    }
  }
  pose.p = t * length_scale;
  return pose;
}

void bvhForwardKinematics(const Bvh& bvh, std::span<const double> frame, std::span<math::SE3> world,
                          double length_scale) {
  // parents precede children in bvh.joints, so one pass suffices
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    const math::SE3 local = bvhLocalPose(bvh, static_cast<int>(j), frame, length_scale);
    const int parent = bvh.joints[j].parent;
    world[j] = parent < 0 ? local : world[static_cast<std::size_t>(parent)] * local;
  }
}

std::vector<math::SE3> bvhWorldPoses(const Bvh& bvh, long long frame, BvhLengthUnit unit) {
  const int f = resolveBvhFrame(bvh, frame);
  std::vector<math::SE3> world(bvh.joints.size());
  bvhForwardKinematics(bvh, bvhFrame(bvh, f), world, unit == BvhLengthUnit::Metre ? bvh.unit_scale_to_m : 1.0);
  return world;
}

namespace {
// horizontal (x, z; only when asked: quadratic in the joints) and vertical (y) extents of the frame's joints
// and End Sites, in file units
std::pair<double, double> bvhExtents(const Bvh& bvh, int frame, std::vector<math::SE3>& world, bool horizontal_too) {
  bvhForwardKinematics(bvh, bvhFrame(bvh, frame), world);
  double horizontal = 0, lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t a = 0; a < world.size(); ++a) {
    lo = std::min(lo, world[a].p.y());
    hi = std::max(hi, world[a].p.y());
    if (horizontal_too)
      for (std::size_t b = a + 1; b < world.size(); ++b)
        horizontal = std::max(horizontal, std::hypot(world[a].p.x() - world[b].p.x(), world[a].p.z() - world[b].p.z()));
  }
  return {horizontal, world.empty() ? 0.0 : hi - lo};
}

struct TPoseTest {
  explicit TPoseTest(const Bvh& bvh) : bvh_(bvh), world_(bvh.joints.size()) {
    for (int f = 0; f < bvh.num_frames; ++f) tallest_ = std::max(tallest_, bvhExtents(bvh, f, world_, false).second);
  }
  bool operator()(int frame) {
    const auto [h, v] = bvhExtents(bvh_, frame, world_, true);
    return v > 0 && h >= kBvhTPoseSpread * v && v >= kBvhTPoseUpright * tallest_;
  }
  const Bvh& bvh_;
  std::vector<math::SE3> world_;
  double tallest_ = 0;
};
}  // namespace

bool bvhIsTPose(const Bvh& bvh, long long frame) {
  const int f = resolveBvhFrame(bvh, frame);
  return TPoseTest(bvh)(f);
}

std::vector<int> bvhTPoseFrames(const Bvh& bvh) {
  TPoseTest is_tpose(bvh);
  std::vector<int> frames;
  for (int f = 0; f < bvh.num_frames; ++f)
    if (is_tpose(f)) frames.push_back(f);
  return frames;
}

int bvhLeadingTPoseFrames(const Bvh& bvh, int from) {
  if (from < 0 || from >= bvh.num_frames) return 0;
  TPoseTest is_tpose(bvh);
  int n = 0;
  while (from + n < bvh.num_frames && is_tpose(from + n)) ++n;
  return n;
}

}  // namespace mannequin::skeleton
