#include "mannequin/core/config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace mannequin::core {

ConfigNode ConfigNode::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ":0: cannot read the file");
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
    throw ConfigError(fmt::format("{}:{}: YAML syntax error: {}", source, e.mark.line + 1, e.msg));
  }
}

int ConfigNode::line() const { return node_.Mark().line >= 0 ? node_.Mark().line + 1 : 0; }

void ConfigNode::fail(const std::string& message) const {
  throw ConfigError(fmt::format("{}:{}: field '{}': {}", file_, line(), path_.empty() ? "<top>" : path_, message));
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
  for (std::size_t i = 0; i < node_.size(); ++i) out.emplace_back(node_[i], file_, fmt::format("{}[{}]", path_, i));
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

double ConfigNode::num() const {
  const std::string s = str();
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used != s.size()) throw std::invalid_argument(s);
    if (!std::isfinite(v)) fail("'" + s + "' is not a finite number");
    return v;
  } catch (const std::logic_error&) {
    fail("'" + s + "' is not a number");
  }
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

bool ConfigNode::boolean() const {
  const std::string s = str();
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  fail("'" + s + "' is not true/false");
}

Eigen::Vector3d ConfigNode::vec3() const {
  const auto it = items();
  if (it.size() != 3) fail(fmt::format("expected [x, y, z], got {} values", it.size()));
  return {it[0].num(), it[1].num(), it[2].num()};
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
  if (!c) return fallback;
  const double v = c->num();
  if (v < lo || v > hi) c->fail(fmt::format("{} is outside [{}, {}]", v, lo, hi));
  return v;
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
