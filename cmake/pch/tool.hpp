// Precompiled header of the tools and the service mains (kind `tool` of mannequin_use_pch).
#pragma once

#include "harness.hpp"

#include <CLI/CLI.hpp>
