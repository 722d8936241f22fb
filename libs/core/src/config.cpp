#include "mannequin/core/config.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace mannequin::core {

namespace {
// shortest text that reads back as `v` (0.5, 1e-05, -1)
std::string text(double v) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), r.ptr);
}
std::string text(long long v) { return std::to_string(v); }
std::string text(std::size_t v) { return std::to_string(v); }
}  // namespace

ConfigNode ConfigNode::load(const std::string& path) {
  errno = 0;
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ":0: cannot read the file" + (errno != 0 ? std::string(" (") + std::strerror(errno) + ")" : ""));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

ConfigNode ConfigNode::parse(const std::string& text, const std::string& source) {
  try {
    YAML::Node n = YAML::Load(text);
    if (!n.IsMap()) throw ConfigError(source + ":1: expected a map of settings at the top level");
    return ConfigNode(n, source);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
}

int ConfigNode::line() const { return node_.Mark().line >= 0 ? node_.Mark().line + 1 : 0; }

std::string ConfigNode::where() const { return file_ + ":" + std::to_string(line()); }

void failAt(const std::string& where, const std::string& field, const std::string& message) {
  throw ConfigError(where + ": field '" + (field.empty() ? "<top>" : field) + "': " + message);
}

void ConfigNode::fail(const std::string& message) const {
  throw ConfigError(where() + ": field '" + (path_.empty() ? "<top>" : path_) + "': " + message);
}

bool ConfigNode::has(const std::string& key) const { return node_.IsMap() && node_[key]; }

std::optional<ConfigNode> ConfigNode::find(const std::string& key) const {
  if (!node_.IsMap()) fail("expected a map");
  YAML::Node c = node_[key];
  if (!c) return std::nullopt;
  return ConfigNode(c, file_, path_.empty() ? key : path_ + "." + key);
}

ConfigNode ConfigNode::operator[](const std::string& key) const {
  auto c = find(key);
  if (!c) fail("missing required key '" + key + "'");
  return *c;
}

std::vector<ConfigNode> ConfigNode::items() const {
  if (!node_.IsSequence()) fail("expected a list");
  std::vector<ConfigNode> out;
  for (std::size_t i = 0; i < node_.size(); ++i) out.emplace_back(node_[i], file_, path_ + "[" + text(i) + "]");
  return out;
}

std::vector<std::string> ConfigNode::keys() const {
  if (!node_.IsMap()) fail("expected a map");
  std::vector<std::string> out;
  for (auto it = node_.begin(); it != node_.end(); ++it) out.push_back(it->first.as<std::string>());
  return out;
}

std::string ConfigNode::str() const {
  if (!node_.IsScalar()) fail("expected a value");
  return node_.Scalar();
}

namespace {
// A YAML float (core schema: .inf, -.inf, .nan in their spellings) or what strtod reads in full; an overflow
// reads as ±inf. false when the text is not a number.
bool parseNumber(const std::string& s, double& v) {
  static const char* const kInf[] = {".inf", ".Inf", ".INF"};
  static const char* const kNan[] = {".nan", ".NaN", ".NAN"};
  const bool sign = !s.empty() && (s[0] == '+' || s[0] == '-');
  const std::string body = sign ? s.substr(1) : s;
  for (const char* k : kInf)
    if (body == k) {
      v = (s[0] == '-' ? -1.0 : 1.0) * std::numeric_limits<double>::infinity();
      return true;
    }
  for (const char* k : kNan)
    if (s == k) {
      v = std::numeric_limits<double>::quiet_NaN();
      return true;
    }
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}
}  // namespace

double ConfigNode::num() const {
  const std::string s = str();
  double v = 0;
  if (!parseNumber(s, v)) fail("'" + s + "' is not a number");
  if (!std::isfinite(v)) fail("'" + s + "' is not a finite number");
  return v;
}

double ConfigNode::positive() const {
  const double v = num();
  if (!(v > 0)) fail("must be > 0, got " + str());
  return v;
}

double ConfigNode::nonNegative() const {
  const double v = num();
  if (!(v >= 0)) fail("must be >= 0, got " + str());
  return v;
}

double ConfigNode::numIn(double lo, double hi) const {
  const double v = num();
  if (v < lo || v > hi) fail(text(v) + " is outside [" + text(lo) + ", " + text(hi) + "]");
  return v;
}

double ConfigNode::numOrInfinity() const {
  const std::string s = str();
  double v = 0;
  if (!parseNumber(s, v) || std::isnan(v)) fail("'" + s + "' is not a number");
  return v;
}

long long ConfigNode::integer() const {
  const std::string s = str();
  try {
    std::size_t used = 0;
    const long long v = std::stoll(s, &used);
    if (used != s.size()) throw std::invalid_argument(s);
    return v;
  } catch (const std::logic_error&) {
    fail("'" + s + "' is not an integer");
  }
}

long long ConfigNode::integerIn(long long lo, long long hi) const {
  const long long v = integer();
  if (v < lo || v > hi) fail(text(v) + " is outside [" + text(lo) + ", " + text(hi) + "]");
  return v;
}

bool ConfigNode::boolean() const {
  const std::string s = str();
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  fail("'" + s + "' is not true/false");
}

Eigen::Vector3d ConfigNode::vec3() const {
  const auto it = items();
  if (it.size() != 3) fail("expected [x, y, z], got " + text(it.size()) + " values");
  return {it[0].num(), it[1].num(), it[2].num()};
}

Eigen::VectorXd ConfigNode::vector(int size) const {
  const auto it = items();
  if (size >= 0 && static_cast<int>(it.size()) != size)
    fail("expected a list of " + std::to_string(size) + " numbers, got " + text(it.size()) + " values");
  Eigen::VectorXd v(static_cast<Eigen::Index>(it.size()));
  for (std::size_t i = 0; i < it.size(); ++i) v(static_cast<Eigen::Index>(i)) = it[i].num();
  return v;
}

Eigen::Matrix3d ConfigNode::rpyDeg() const {
  const Eigen::Vector3d a = vec3() * (3.14159265358979323846 / 180.0);
  return (Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::size_t ConfigNode::choice(const std::vector<std::string>& options) const {
  const std::string s = str();
  std::string list;
  for (std::size_t i = 0; i < options.size(); ++i) {
    if (options[i] == s) return i;
    list += (i == 0 ? "" : i + 1 == options.size() ? " or " : ", ") + options[i];
  }
  fail("expected " + list + ", got '" + s + "'");
}

std::vector<std::string> ConfigNode::strings() const {
  if (node_.IsScalar()) return {str()};
  std::vector<std::string> out;
  for (const ConfigNode& n : items()) out.push_back(n.str());
  return out;
}

std::string ConfigNode::get(const std::string& key, const std::string& fallback) const {
  auto c = find(key);
  return c ? c->str() : fallback;
}
double ConfigNode::get(const std::string& key, double fallback) const {
  auto c = find(key);
  return c ? c->num() : fallback;
}
long long ConfigNode::get(const std::string& key, long long fallback) const {
  auto c = find(key);
  return c ? c->integer() : fallback;
}
bool ConfigNode::get(const std::string& key, bool fallback) const {
  auto c = find(key);
  return c ? c->boolean() : fallback;
}

double ConfigNode::getIn(const std::string& key, double fallback, double lo, double hi) const {
  auto c = find(key);
  return c ? c->numIn(lo, hi) : fallback;
}

void ConfigNode::allowOnly(const std::vector<std::string>& allowed) const {
  if (!node_.IsMap()) fail("expected a map");
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string k = it->first.as<std::string>();
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == k;
    if (!ok) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      ConfigNode(it->first, file_, path_.empty() ? k : path_ + "." + k).fail("unknown key (expected one of: " + list + ")");
    }
  }
}

}  // namespace mannequin::core
