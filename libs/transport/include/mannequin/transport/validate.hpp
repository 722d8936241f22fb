#pragma once
/// \file validate.hpp
/// \brief Content checks of incoming messages, used as Subscriber validators: "" when the message
/// is usable, else the reason (the message is then counted as malformed and never reaches the loop).
#include <string>

#include "mannequin/transport/topics.hpp"

namespace mannequin::transport {

/// Bodies have names, tracked bodies have finite poses with unit quaternions (NaN poses rejected),
/// quality finite. An untracked body's pose is not checked.
std::string validateMocapFrame(const v1::MocapFrame& frame);
/// Finite points, normals and distances.
std::string validateContactSet(const v1::ContactSet& contacts);
/// Every body pose finite with a unit quaternion.
std::string validateCollisionQuery(const v1::CollisionQuery& query);
/// A name (1–128 characters, no control characters) and a value of at most 4096 bytes.
std::string validateTrigger(const v1::Trigger& trigger);

}  // namespace mannequin::transport
