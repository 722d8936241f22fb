// Precompiled header of the test executables (kind `test` of mannequin_use_pch).
#pragma once

#include "harness.hpp"

#include <gtest/gtest.h>
