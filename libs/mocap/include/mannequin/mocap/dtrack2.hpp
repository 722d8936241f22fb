#pragma once
/// \file dtrack2.hpp
/// \brief ART DTrack2 ASCII UDP output ("fr", "ts", "6dcal", "6d" lines), the live protocol of ART
/// optical trackers in VR rooms.
///
/// One UDP datagram = one frame, lines separated by CR LF (or LF):
///   fr 518169                                  frame counter
///   ts 30331.359222                            timestamp, s since midnight (UTC) of the tracker clock
///   6dcal 3                                    number of calibrated standard bodies (optional)
///   6d 1 [45 1.000][-5.026 695.186 763.716 -7.7879 -10.9331 -3.3467][0.980175 -0.032183 ... 0.972793]
/// A "6d" line: the number of bodies in the line, then per body three blocks:
///   [id quality] [sx sy sz η θ φ] [b0 ... b8]
/// id from 0, quality in [0, 1] (a body not listed, or with quality < 0, is not tracked); position in mm
/// in the room frame; Euler angles in degrees (R = Rx(η) Ry(θ) Rz(φ)), ignored here; rotation matrix
/// b0..b8 column-wise (b0 b1 b2 is the first column). Newer firmware may send only [sx sy sz] in the
/// second block: both are accepted. Other lines (6df, 6df2, 6dmt, 3d, gl, 6di, st, ...) are skipped.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mannequin/mocap/source.hpp"

namespace mannequin::mocap {

/// One standard body of a 6d line.
struct DTrackBody {
  int id = -1;
  double quality = -1.0;
  math::Vector3 position_mm = math::Vector3::Zero();
  math::Matrix3 rotation = math::Matrix3::Identity();
};

/// One parsed datagram.
struct DTrackDatagram {
  std::optional<std::uint32_t> frame_counter;   ///< "fr"
  std::optional<double> timestamp;              ///< "ts", s
  std::optional<int> calibrated_bodies;         ///< "6dcal"
  std::vector<DTrackBody> bodies;               ///< "6d"
};

/// Parses one datagram. Returns "" on success, else "line N: what is wrong" (then `out` is unusable).
/// Rejects non-finite numbers, non-orthonormal rotation matrices (|RᵀR − I| > 1e-3), negative or
/// duplicate ids, counts that do not match the blocks, and datagrams without an "fr" line.
std::string parseDTrack(std::string_view datagram, DTrackDatagram& out);

struct DTrackOptions {
  std::string bind_address = "127.0.0.1";
  int port = 5000;            ///< 0: ephemeral (see DTrackSource::port())
  double unit_to_m = 0.001;   ///< DTrack sends mm
  /// DTrack id → body name; ids not listed are ignored.
  std::vector<std::pair<int, std::string>> bodies;
  /// Rotation from the tracker's room frame to ours (identity when the room is calibrated z up).
  math::Matrix3 room_rotation = math::Matrix3::Identity();
};

/// Receives DTrack2 datagrams on a UDP socket (Asio) and turns them into frames. A configured body
/// that is absent from a frame is reported untracked with its last tracked pose.
class DTrackSource final : public Source {
 public:
  /// \throws std::runtime_error if the socket cannot be bound.
  explicit DTrackSource(DTrackOptions options);
  ~DTrackSource() override;
  std::optional<Frame> next(std::chrono::microseconds timeout) override;
  bool finished() const override { return false; }
  std::string kind() const override { return "dtrack2"; }
  std::string describe() const override;
  /// The UDP port actually bound.
  int port() const;
  std::uint64_t malformedDatagrams() const { return malformed_; }
  /// The Frame of a parsed datagram (updates the last known poses).
  Frame toFrame(const DTrackDatagram& frame, std::int64_t receive_ns);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  DTrackOptions options_;
  std::vector<Body> last_;
  std::uint64_t malformed_ = 0;
};

}  // namespace mannequin::mocap
