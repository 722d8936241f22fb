#pragma once
/// \file c3d_source.hpp
/// \brief A C3D marker capture played as a tracker: each rigid body is a cluster of markers (named in
/// a mapping YAML, configs/mappings/*.yaml, key `markers`), its pose fitted to the cluster's visible
/// markers every frame; a cluster with fewer than three usable markers is occluded in that frame.
///
/// Body frame: at the cluster's reference frame (among the frames of the played range with the most
/// of its markers valid, the first whose marker-to-marker distances are closest to their medians, to
/// 0.1 mm) the body's origin is the centroid of the markers visible there and its axes
/// are the lab axes; every other frame's pose is the least-squares rigid motion (Kabsch, SVD) taking
/// the reference markers onto the visible ones. Coordinates: the file's lab frame (C3D labs are z up)
/// scaled to metres. A marker that misses the fitted body by more than max_marker_error_m is dropped
/// as a gap (a mislabelled or ghost marker). An occluded body keeps its last tracked pose (identity if never seen),
/// tracked = false; quality = markers used / markers of the cluster.
#include <cstdint>
#include <string>
#include <vector>

#include "mannequin/math/se3.hpp"
#include "mannequin/mocap/c3d.hpp"
#include "mannequin/mocap/source.hpp"

namespace mannequin::mocap {

/// One rigid body: its name and the labels of its markers (at least three).
struct C3dCluster {
  std::string body;
  std::vector<std::string> markers;
  std::string where;  ///< FILE:LINE of the mapping entry, for errors found against a capture
};

/// A mapping file: `name`, optional `unit` (mm, cm, m: overrides POINT:UNITS), `markers` (body: [labels]).
struct C3dMapping {
  std::string name;
  double unit_scale_to_m = 0.0;  ///< 0: from the file's POINT:UNITS
  std::vector<C3dCluster> bodies;
};

/// \throws core::ConfigError "FILE:LINE: field 'markers.x': message" (unknown key or unit, a cluster
/// of fewer than 3 markers, a marker listed twice, no bodies).
C3dMapping parseC3dMapping(const std::string& yaml_text, const std::string& source);
C3dMapping loadC3dMapping(const std::string& path);

/// Metres per unit for a POINT:UNITS string (mm, cm, m, case-insensitive), 0 if unknown.
double c3dUnitScale(const std::string& units);

struct C3dSourceOptions {
  std::string file;
  C3dMapping mapping;
  double rate = 1.0;  ///< playback rate factor; > 0
  bool loop = false;
  long long start_frame = 0;
  long long end_frame = -1;  ///< inclusive; negative counts from the end (of the frames present)
  bool paced = true;
  bool mark_calibration = true;  ///< flag the first frame as the calibration pose
  /// A marker farther than this from where the fitted body puts it is a gap in that frame (the worst
  /// dropped, the fit redone while more than 3 remain; with 3 the body is occluded). Metres.
  double max_marker_error_m = 0.015;
};

class C3dSource final : public Source {
 public:
  /// \throws C3dError for a bad file; core::ConfigError naming the mapping's FILE:LINE for a marker
  /// the file lacks; std::invalid_argument for a bad range, rate, unknown units, or a cluster whose
  /// markers are never three visible and not collinear in one frame.
  explicit C3dSource(C3dSourceOptions options);
  std::optional<Frame> next(std::chrono::microseconds timeout) override;
  bool finished() const override { return finished_; }
  std::string kind() const override { return "c3d"; }
  std::string describe() const override;
  const C3d& c3d() const { return c3d_; }
  /// The frame of 0-based file frame `frame` (in the played range) after `loops` loops, with the
  /// occluded bodies at their last tracked pose in file order (no side effect).
  Frame frameAt(int frame, std::uint64_t loops) const;
  /// The fitted pose of body `body` at `frame`, false if occluded there; `used` markers.
  bool fit(int frame, std::size_t body, math::SE3& pose, int& used) const;
  /// The reference frame of each body (see the file comment).
  const std::vector<int>& referenceFrames() const { return ref_frame_; }

 private:
  Frame makeFrame(int frame, std::uint64_t loops, std::vector<math::SE3>& last) const;

  C3dSourceOptions options_;
  C3d c3d_;
  double scale_ = 1.0;  ///< metres per file unit
  std::vector<std::vector<int>> marker_index_;             ///< per body: point indices
  std::vector<std::vector<math::Vector3>> body_markers_;   ///< per body: marker in the body frame (m); NaN if unused
  std::vector<int> ref_frame_;
  int first_ = 0, last_ = 0;
  int frame_ = 0;
  std::uint64_t loops_ = 0;
  bool finished_ = false;
  bool started_ = false;
  std::int64_t start_ns_ = 0;
  std::vector<math::SE3> last_pose_;
};

}  // namespace mannequin::mocap
