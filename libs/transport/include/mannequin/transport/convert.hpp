#pragma once
/// \file convert.hpp
/// \brief Conversions between in-process types (SE3, Vector3, mocap::Frame) and the mannequin.v1 messages.
/// Poses keep their frames: a Pose message holds the same frame-in-parent transform as the SE3.
#include <mannequin/v1/header.pb.h>
#include <mannequin/v1/mocap.pb.h>

#include "mannequin/math/se3.hpp"
#include "mannequin/mocap/frame.hpp"

namespace mannequin::transport {

void toMsg(const math::Vector3& v, v1::Vec3& out);
void toMsg(const math::SE3& pose, v1::Pose& out);
math::Vector3 fromMsg(const v1::Vec3& v);
/// The quaternion is normalised (a zero quaternion gives the identity).
math::SE3 fromMsg(const v1::Pose& pose);

/// The wire form of a frame: header.stamp_ns = capture time (the publisher fills the rest of the header).
void toMsg(const mocap::Frame& frame, const std::string& source_kind, v1::MocapFrame& out);
/// The frame a message carries, with Header.sequence and send_time_ns (poses normalised as above).
mocap::Frame fromMsg(const v1::MocapFrame& msg);

/// "" if every number of the pose is finite and its quaternion has a norm within `tolerance` of 1,
/// else what is wrong ("position is not finite", "quaternion norm 0.3").
std::string checkPose(const v1::Pose& pose, double tolerance = 1e-3);

}  // namespace mannequin::transport
