#pragma once
// The captures of data/bvh/ shipped with the checkout (MANNEQUIN_SOURCE_DIR, set by ctest).
#include <string>

#include "../common/source.hpp"

namespace mannequin::testing {

/// data/bvh/<name> in the checkout.
inline std::string bvhDataPath(const std::string& name) { return sourcePath("data/bvh/" + name); }

}  // namespace mannequin::testing
