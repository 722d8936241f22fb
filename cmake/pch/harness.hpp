// Precompiled for the harness code (cmake/MannequinHelpers.cmake, mannequin_use_pch): the third-party and
// standard headers that the test executables, the tools and the service mains all parse. Only headers that
// rarely change belong here: the project's own headers would rebuild every harness source on each edit.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <google/protobuf/message.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>
