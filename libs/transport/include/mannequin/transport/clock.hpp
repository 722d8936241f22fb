#pragma once
/// \file clock.hpp
/// \brief The cluster's two clocks (core/clock.hpp), under the transport namespace where messages are stamped.
#include "mannequin/core/clock.hpp"

namespace mannequin::transport {

using core::steadyNs;
using core::wallNs;

}  // namespace mannequin::transport
