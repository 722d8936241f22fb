#pragma once
/// \file force_plate.hpp
/// \brief The force plates of a C3D file (FORCE_PLATFORM group, C3D user guide): per plate and per analog
/// sample, the ground reaction on the subject, its centre of pressure and the free moment, in the lab frame.
///
/// Types: 1 (Fx Fy Fz, CoP x y, Tz), 2 (Fx Fy Fz Mx My Mz, AMTI), 3 (Kistler: fx12 fx34 fy14 fy23 fz1..fz4),
/// 4 (type 2 after the 6 × 6 CAL_MATRIX). Channels are the analog channels of FORCE_PLATFORM:CHANNEL,
/// scaled as C3d::analog gives them (N and N·length unit), less their mean over the FORCE_PLATFORM:ZERO
/// frames (the unloaded baseline; no baseline when ZERO is absent or 0 0).
///
/// Frames. The plate frame has its x and y axes in the working surface and its z axis into the plate
/// (down), as the corners give it: CORNERS lists the four corners in the lab frame in the order
/// (+x +y), (−x +y), (−x −y), (+x −y) of the plate frame. ORIGIN (types 2 and 4) is the centre of the
/// working surface seen from the transducer's origin, in the plate frame (its z is negative: the surface
/// is above the origin; a file storing it with z > 0 has it turned round, as Visual3D and ezc3d do); for
/// type 3 it is (a, b, az0), the sensors' offsets and the surface's height; type 1's CoP channels are
/// from the centre of the surface. CAL_MATRIX (type 4) is stored column by column (first index: row).
/// ZERO is a range of 1-based 3D frames ("0 10" reads as 1..10, a range past the last frame is cut there).
/// The channels give the reaction of the plate on the subject in the plate frame (as BTK reads them: on the
/// c3d.org sample walk they push the walker up, Fz < 0 along the plate's downward z); the reaction
/// reported here is that wrench rotated to the lab frame.
///
/// Units: force in N; CoP and corners in the file's length unit (POINT:UNITS); moments in N × that unit.
#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "mannequin/mocap/c3d.hpp"

namespace mannequin::mocap {

/// One plate's description, checked and put in the lab frame.
struct ForcePlate {
  int type = 0;                                   ///< 1, 2, 3 or 4
  std::vector<int> channels;                      ///< 0-based analog channels (6, or 8 for type 3)
  std::array<Eigen::Vector3d, 4> corners;         ///< lab frame
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< FORCE_PLATFORM:ORIGIN (plate frame)
  Eigen::Matrix<double, 6, 6> calibration = Eigen::Matrix<double, 6, 6>::Identity();  ///< type 4
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< columns: the plate's x, y, z in the lab frame
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    ///< centre of the working surface (lab frame)
  std::vector<double> baseline;                         ///< per channel of `channels`, subtracted
  int zero_first = 0, zero_last = 0;                    ///< FORCE_PLATFORM:ZERO (1-based frames; 0 0: none)

  /// The unit normal of the working surface pointing out of the plate, towards the subject (−z).
  Eigen::Vector3d normal() const { return -axes.col(2); }
};

/// The reaction on the subject at one instant (lab frame).
struct PlateReaction {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< N
  /// Centre of pressure on the working surface; NaN while the normal force is below the threshold.
  Eigen::Vector3d cop = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Moment about the surface normal through the CoP (N × length unit); 0 while the CoP is undefined.
  double free_moment = 0.0;
  /// The reaction's component along the outward surface normal (N, > 0 when the subject stands on the plate).
  double normal_force = 0.0;
};

/// The plates of a file and their reactions per analog sample.
struct ForcePlates {
  std::vector<ForcePlate> plates;
  double rate = 0.0;  ///< analog samples per second
  int subframes = 0;  ///< analog samples per 3D frame
  int samples = 0;    ///< analog samples present
  /// Below this normal force (N) a plate is unloaded: no CoP (20 N, the usual gait-lab threshold).
  double threshold = 20.0;
  /// The plate's wrench (the channels' reaction, plate frame, about the plate's reference point: Fx Fy Fz
  /// Mx My Mz) per sample, after the baseline, types 1, 3 and 4 converted; plates × samples.
  std::vector<Eigen::Matrix<double, 6, 1>> wrench;

  const Eigen::Matrix<double, 6, 1>& wrenchAt(int plate, int sample) const {
    return wrench[static_cast<std::size_t>(plate) * static_cast<std::size_t>(samples) + static_cast<std::size_t>(sample)];
  }
  /// The reaction on the subject from plate `plate` at analog sample `sample`.
  /// \throws std::out_of_range for a plate or sample the file does not have.
  PlateReaction reaction(int plate, int sample) const;
  /// The reaction from the plate's wrench averaged over the analog samples of 0-based 3D frame `frame`.
  /// \throws std::out_of_range for a plate or frame the file does not have.
  PlateReaction frameReaction(int plate, int frame) const;
  /// The reaction from a plate wrench (as stored in `wrench`).
  PlateReaction reactionOf(int plate, const Eigen::Matrix<double, 6, 1>& w) const;
};

/// Decodes the FORCE_PLATFORM group of `c3d`. A file without the group (or with USED = 0) has no plates.
/// \throws C3dError naming the file, the parameter's byte offset and what is wrong: an unknown TYPE, a
/// CHANNEL count that does not fit the type or names a channel the file does not have, CORNERS or ORIGIN
/// too short or not finite, degenerate corners, a type 4 plate without CAL_MATRIX, a plate whose channels
/// hold no analog data (ANALOG:USED absent), ZERO outside the frames.
ForcePlates readForcePlates(const C3d& c3d);

}  // namespace mannequin::mocap
