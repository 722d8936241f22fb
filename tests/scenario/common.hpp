#pragma once
#include <cstdlib>
#include <string>

namespace scenario_test {

// the checkout (tests run there; MANNEQUIN_SOURCE_DIR when set)
inline std::string sourceDir() {
  const char* d = std::getenv("MANNEQUIN_SOURCE_DIR");
  return d != nullptr ? d : ".";
}

}  // namespace scenario_test
