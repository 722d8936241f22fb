#pragma once
/// \file bvh_drive.hpp
/// \brief Drives a mannequin from a BVH capture by transferring segment orientations
/// (joint-space transfer, the baseline before the priority-IK retargeting of libs/ik).
///
/// For every mapped segment s driven by BVH joint b:
/// - axes: A maps the BVH world (y up, actor facing +z) onto the mannequin world (z up, facing +x);
/// - calibration at the rest poses (BVH: all channels zero; mannequin: zero configuration):
///   C_s is the smallest rotation taking the mannequin's rest bone direction onto the BVH's
///   (so a T-pose capture drives an arms-down mannequin);
/// - each frame: R_s = A R_b(t) R_b(rest)ᵀ Aᵀ C_s, the world orientation asked of segment s;
/// - joint coordinates: ball joints take log(R_parentᵀ R_s); chains of revolute joints take the
///   least-squares angles (Gauss–Newton on the rotation error); then joint limits clamp.
/// The pelvis (root) position follows the BVH root, scaled by the ratio of hip heights.
#include <string>
#include <utility>
#include <vector>

#include "mannequin/skeleton/bvh.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

/// Which BVH joint drives which mannequin segment (configs/mappings/*.yaml).
struct BvhDriveMap {
  std::string name;
  double unit_scale_to_m = 0.01;  ///< metres per BVH file unit
  /// (segment, BVH joint) pairs; the first must be the root segment (pelvis).
  std::vector<std::pair<std::string, std::string>> segments;
};

/// Parses a mapping config (keys: name, unit or scale_to_m, segments).
/// \throws core::ConfigError "FILE:LINE: field 'key': message" (unknown key, unknown unit, no segments...).
BvhDriveMap parseBvhDriveMap(const std::string& yaml_text, const std::string& source);
/// Reads and parses a mapping file. \throws core::ConfigError (unreadable file included, line 0).
BvhDriveMap loadBvhDriveMap(const std::string& path);

/// Per-frame result of the transfer.
struct BvhDriveFrame {
  VectorX q;                      ///< (nq) mannequin configuration
  double max_error_deg = 0.0;     ///< worst segment orientation error after limits (deg)
  double mean_error_deg = 0.0;    ///< mean over the mapped segments (deg)
  int clamped = 0;                ///< coordinates clamped by joint limits
  std::vector<double> error_deg;  ///< per mapped segment, in map order (deg)
};

/// The transfer, calibrated once for a model, a capture and a map.
class BvhDriver {
 public:
  /// \throws std::invalid_argument naming any unknown segment or BVH joint, a root segment that
  /// is not the model's root, or a map whose unit is not finite and > 0.
  BvhDriver(const Model& model, const Bvh& bvh, const BvhDriveMap& map);

  /// Configuration for frame `frame` (negative counts from the end). \throws std::out_of_range.
  BvhDriveFrame drive(long long frame);

  /// Ratio mannequin hip height / actor hip height used for the root position.
  double scale() const { return scale_; }
  /// Names of the mapped segments, in map order (the order of BvhDriveFrame::error_deg).
  std::vector<std::string> segmentNames() const;

 private:
  struct Link {
    int segment;       // mannequin segment
    int bvh;           // BVH joint
    math::Matrix3 C;   // rest calibration (mannequin world)
    math::Matrix3 rest_inv;  // R_b(rest)ᵀ
    std::vector<int> chain;  // joints its orientation sets, root side first
  };
  const Model& model_;
  const Bvh& bvh_;
  std::vector<Link> links_;
  std::vector<int> link_of_joint_;   // joint index → link driving the segment it carries (-1)
  std::vector<math::SE3> bvh_world_;
  math::Matrix3 A_;
  double scale_ = 1.0;
  double length_scale_ = 0.01;
};

}  // namespace mannequin::skeleton
