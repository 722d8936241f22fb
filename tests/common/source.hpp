#pragma once
// Where the tests find the checkout's files (the standard mannequins: mannequins.hpp).
// ctest sets MANNEQUIN_SOURCE_DIR (and runs the tests in the checkout); without it, the working directory.
#include <cstdlib>
#include <string>

namespace mannequin::testing {

/// The checkout's root.
inline std::string sourceDir() {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return root != nullptr ? std::string(root) : std::string(".");
}

/// A file of the checkout, from its path relative to the root.
inline std::string sourcePath(const std::string& relative) { return sourceDir() + "/" + relative; }

/// configs/mannequins/<file> in the checkout (e.g. "male_50th.yaml").
inline std::string mannequinConfigPath(const std::string& file) { return sourcePath("configs/mannequins/" + file); }

}  // namespace mannequin::testing
