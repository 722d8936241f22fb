#pragma once
#include <string>

#include "../common/source.hpp"

namespace scenario_test {

using mannequin::testing::sourceDir;

}  // namespace scenario_test
