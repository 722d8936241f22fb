#pragma once
// The standard mannequins of configs/mannequins/, built once per test process.
#include <map>
#include <string>

#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/model.hpp"

#include "source.hpp"

namespace mannequin::testing {

/// configs/mannequins/<name>.yaml built once per test process (e.g. "male_50th").
inline const skeleton::Model& standardMannequin(const std::string& name) {
  static std::map<std::string, skeleton::Model> built;
  auto it = built.find(name);
  if (it == built.end())
    it = built.emplace(name, skeleton::buildMannequin(skeleton::loadMannequinSpec(sourcePath("configs/mannequins/" + name + ".yaml"))))
             .first;
  return it->second;
}

/// The 50th-percentile male (configs/mannequins/male_50th.yaml).
inline const skeleton::Model& male50() { return standardMannequin("male_50th"); }

}  // namespace mannequin::testing
