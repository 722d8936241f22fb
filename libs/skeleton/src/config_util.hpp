#pragma once
// Internal helpers shared by the skeleton's YAML config readers (mannequins, mappings).
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>
#include <string>

#include "mannequin/skeleton/anthropometry.hpp"  // ConfigError

namespace mannequin::skeleton::detail {

/// Parses YAML text; a syntax error becomes ConfigError "SOURCE:LINE: invalid YAML: ...".
inline YAML::Node parseYaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
}

/// Whole file as text; an unreadable file becomes ConfigError "PATH:0: cannot open WHAT".
inline std::string readConfigFile(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ":0: cannot open " + what);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace mannequin::skeleton::detail
