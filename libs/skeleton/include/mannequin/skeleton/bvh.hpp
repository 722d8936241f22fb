#pragma once
/// \file bvh.hpp
/// \brief Reader and forward kinematics for BVH motion captures (Biovision Hierarchy, the
/// interchange format of the CMU database and most motion-capture tools).
///
/// Conventions (the usual BVH ones, see docs/bvh.md):
/// - Lengths (OFFSET, position channels) are in the FILE's units; `Bvh::unit_scale_to_m`
///   says how many metres one file unit is (it is not stored in the file: the caller tells).
/// - Angles in the file are in degrees. Rotation channels compose in the order listed:
///   `CHANNELS 3 Zrotation Xrotation Yrotation` gives R_local = Rz(a1) · Rx(a2) · Ry(a3),
///   each a right-handed rotation about the joint's local axis.
/// - Position channels ADD to the joint's OFFSET: t_local = offset + (Xposition, Yposition,
///   Zposition), whatever their place in the channel list (translation is applied first).
/// - Joint frames: oMi = oMparent · T(t_local) · R_local. The origin of frame i is the joint
///   centre in world coordinates; its axes are the joint's rotated axes. An End Site has
///   T(offset) only (no channels).
/// - Errors found while reading throw BvhError "FILE:LINE: expected X, got 'Y'".
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "mannequin/math/se3.hpp"

namespace mannequin::skeleton {

/// A malformed BVH input: carries the source name and the 1-based line of the problem.
/// what() is "FILE:LINE: message".
class BvhError : public std::runtime_error {
 public:
  BvhError(std::string file, int line, const std::string& message);
  /// Source name given to the reader (a path, or "<string>").
  const std::string& file() const noexcept { return file_; }
  /// 1-based line number of the offending token (0 when not tied to a line, e.g. I/O).
  int line() const noexcept { return line_; }
  /// The message without the "FILE:LINE: " prefix.
  const std::string& message() const noexcept { return message_; }

 private:
  std::string file_;
  int line_;
  std::string message_;
};

/// One BVH channel. Positions are in file units, rotations in degrees.
enum class BvhChannel : std::uint8_t { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };

/// The channel's name as written in a BVH file ("Xposition", ...).
std::string_view bvhChannelName(BvhChannel channel);

/// Length units commonly found in BVH files, with their size in metres.
enum class BvhUnit : std::uint8_t {
  Metre,       ///< 1 m
  Centimetre,  ///< 0.01 m (mocapbank, Mixamo, most exporters)
  Inch,        ///< 0.0254 m
  Cmu,         ///< 0.056444 m: the CMU database's unit (its bone lengths are in inches / 0.45)
};

/// Metres per file unit for a BvhUnit.
double bvhUnitScale(BvhUnit unit);

/// Options of the reader.
struct BvhReadOptions {
  /// Metres per file unit, stored in Bvh::unit_scale_to_m. Must be finite and > 0.
  double unit_scale_to_m = 0.01;
};

/// A joint of the BVH hierarchy (ROOT, JOINT or End Site).
struct BvhJoint {
  std::string name;                  ///< as in the file (may contain ':'); empty for an End Site
  int parent = -1;                   ///< index in Bvh::joints, -1 for the root
  math::Vector3 offset = math::Vector3::Zero();  ///< origin in the parent's frame, file units
  std::vector<BvhChannel> channels;  ///< in file order (End Sites have none)
  int first_channel = 0;             ///< index of its first value in a frame row
  bool end_site = false;             ///< true for an End Site (a segment's tip, not a joint)
  int line = 0;                      ///< 1-based line of its ROOT/JOINT/End keyword
};

/// A parsed BVH file: hierarchy and motion.
struct Bvh {
  std::string source;            ///< file name or the name given to parseBvh
  std::vector<BvhJoint> joints;  ///< depth-first file order: a parent precedes its children; joints[0] is the ROOT
  int num_channels = 0;          ///< values per frame (sum of the joints' channel counts)
  int num_frames = 0;            ///< number of frames (may be 0)
  double frame_time = 0.0;       ///< seconds between frames (> 0)
  double unit_scale_to_m = 0.01; ///< metres per file unit (from BvhReadOptions)
  /// Frame values, row-major num_frames × num_channels, in file order and units (degrees).
  std::vector<double> motion;
};

/// Parses BVH text held in memory. `source` names it in errors.
/// Accepts LF, CRLF and CR line ends, tabs and extra whitespace, numbers such as ".5" or "+1e-3",
/// any channel order, 0–6 channels per joint, End Sites, zero offsets and 0 frames.
/// \throws BvhError on any malformed input (the text is never partially accepted).
/// \throws std::invalid_argument if options.unit_scale_to_m is not finite and > 0.
Bvh parseBvh(std::string_view text, const std::string& source = "<string>", const BvhReadOptions& options = {});

/// Reads and parses a BVH file. \throws BvhError (line 0 if the file cannot be read).
Bvh readBvhFile(const std::string& path, const BvhReadOptions& options = {});

/// Number of ROOT and JOINT entries (End Sites excluded).
int bvhJointCount(const Bvh& bvh);

/// Index in bvh.joints of the ROOT/JOINT named `name`, or -1.
int findBvhJoint(const Bvh& bvh, std::string_view name);

/// Resolves a frame index: 0..num_frames-1 as is, negative counts from the end (-1 = last).
/// \throws std::out_of_range if it names no frame.
int resolveBvhFrame(const Bvh& bvh, long long frame);

/// The values of frame `frame` (0-based, not negative). \pre 0 <= frame < num_frames.
std::span<const double> bvhFrame(const Bvh& bvh, int frame);

/// Rotation of `angle_deg` degrees about the x (axis 0), y (1) or z (2) axis; exact at
/// multiples of 90°.
math::Matrix3 bvhAxisRotation(int axis, double angle_deg);

/// Pose of joint j in its parent's frame for one frame's values: p = offset + position
/// channels, R = product of the rotation channels in listed order. Lengths × length_scale.
math::SE3 bvhLocalPose(const Bvh& bvh, int joint, std::span<const double> frame, double length_scale = 1.0);

/// Forward kinematics: world pose oMi of every entry of bvh.joints (End Sites included) for one
/// frame's values, lengths multiplied by length_scale (1 = file units, bvh.unit_scale_to_m = metres).
/// Does not allocate. \pre world.size() == bvh.joints.size(), frame.size() == num_channels.
void bvhForwardKinematics(const Bvh& bvh, std::span<const double> frame, std::span<math::SE3> world,
                          double length_scale = 1.0);

/// Length unit of poses returned by bvhWorldPoses.
enum class BvhLengthUnit : std::uint8_t { File, Metre };

/// World poses of every entry of bvh.joints at frame `frame` (negative = from the end), with
/// positions in file units or metres. \throws std::out_of_range for a bad frame.
std::vector<math::SE3> bvhWorldPoses(const Bvh& bvh, long long frame, BvhLengthUnit unit = BvhLengthUnit::File);

/// A converter's T-pose (arms spread horizontally, standing upright; e.g. the frame 0 that cgspeed's CMU
/// conversions add before the capture). Over every entry of bvh.joints (End Sites included) at one frame:
/// the horizontal extent h (largest distance between two entries projected on the floor, the plane normal to
/// the file's y axis) and the vertical extent v (along y). A frame is a T-pose when h ≥ kBvhTPoseSpread · v
/// (arm span is about the stature: h/v ≈ 1; standing arms down ≈ 0.3, a stride ≈ 0.5) and it stands upright:
/// v ≥ kBvhTPoseUpright · the largest v of the capture (a stoop, where the trunk is horizontal, also has a
/// large h/v, but a small v). Names no joint, so it holds for any skeleton.
inline constexpr double kBvhTPoseSpread = 0.8;
inline constexpr double kBvhTPoseUpright = 0.9;
/// Whether frame `frame` (negative = from the end) is a T-pose. Each call measures every frame of the capture
/// (for its largest v); to test many frames, bvhTPoseFrames. \throws std::out_of_range for a bad frame.
bool bvhIsTPose(const Bvh& bvh, long long frame);
/// Every frame that is a T-pose, in increasing order (two passes over the capture).
std::vector<int> bvhTPoseFrames(const Bvh& bvh);
/// How many frames from `from` on (resolved, not negative) are T-poses before the first that is not; stops
/// at the last frame (all T-poses: num_frames − from).
int bvhLeadingTPoseFrames(const Bvh& bvh, int from);

}  // namespace mannequin::skeleton
