#pragma once
/// \file bvh_write.hpp
/// \brief Writes a mannequin's motion as a standard BVH file (HIERARCHY + MOTION) that other
/// tools (Blender, MotionBuilder, bvh viewers) open, and that readBvhFile reads back.
///
/// - one BVH JOINT per model joint, same names and tree; End Site at the distal end of the
///   segment's capsule for leaf joints;
/// - axes: BVH world y up, facing +z; the mannequin's x (forward) → BVH +z, y (left) → BVH +x,
///   z (up) → BVH +y; every transform is conjugated by that change of axes;
/// - lengths in centimetres; root channels Xposition Yposition Zposition Zrotation Xrotation
///   Yrotation, other joints Zrotation Xrotation Yrotation (degrees), R = Rz Rx Ry;
/// - OFFSET of a joint = its placement translation; the rotation channels encode the whole local
///   rotation (placement rotation × joint rotation), so the BVH rest pose (all zeros) is not the
///   mannequin's anatomical posture unless placements have identity rotations.
#include <ostream>
#include <string>
#include <vector>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

/// The change of axes mannequin world → BVH world (rows: BVH x, y, z).
Matrix3 mannequinToBvhAxes();

/// Writes the motion. \param frames configurations (nq each). \param frame_time seconds per frame.
/// \throws std::invalid_argument on a wrong-size or non-finite configuration (naming the frame),
/// or a frame_time that is not finite and > 0.
void writeMannequinBvh(std::ostream& out, const Model& model, const std::vector<VectorX>& frames, double frame_time);

/// Same to a file, written to FILE.tmp and renamed, so a failure never leaves a partial file.
/// \throws std::runtime_error if the file cannot be written.
void writeMannequinBvhFile(const std::string& path, const Model& model, const std::vector<VectorX>& frames,
                           double frame_time);

}  // namespace mannequin::skeleton
