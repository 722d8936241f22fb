#pragma once
/// \file c3d.hpp
/// \brief C3D reader (the biomechanics lab standard, https://www.c3d.org): the 512-byte header, the
/// parameter section (groups and parameters, looked up by name, case-insensitive) and the 3D point
/// samples of every frame, for the three processor formats of the spec (Intel 84, DEC/VAX 85 with VAX
/// F floats converted to IEEE, SGI/MIPS 86 big endian) and both storages (int16 scaled by POINT:SCALE,
/// float when POINT:SCALE is negative), and the analog samples (ANALOG group: channels, subframes, SCALE,
/// OFFSET, GEN_SCALE, FORMAT) that force plates (force_plate.hpp) are decoded from.
///
/// Untrusted input: every size is checked against the bytes present before anything is allocated
/// from it; a malformed file throws C3dError naming the file, the byte offset and what is wrong. A
/// file whose data stops before its declared last frame is not an error: the whole frames present
/// are read and `truncated` is set.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mannequin::mocap {

/// A malformed C3D file: what() is "FILE: byte OFFSET: what is wrong".
class C3dError : public std::runtime_error {
 public:
  C3dError(std::string file, std::size_t offset, const std::string& what);
  const std::string& file() const { return file_; }
  std::size_t offset() const { return offset_; }
  /// The message without the "FILE: byte OFFSET: " prefix.
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  std::size_t offset_;
  std::string reason_;
};

/// The processor type byte of the parameter section (83 + n).
enum class C3dProcessor : std::uint8_t { kIntel = 84, kDec = 85, kMips = 86 };
enum class C3dStorage : std::uint8_t { kInt16, kFloat };

/// "intel", "dec", "mips".
const char* c3dProcessorName(C3dProcessor p);
/// "int16", "float".
const char* c3dStorageName(C3dStorage s);

/// One parameter: its values decoded to host form (type -1 char, 1 byte, 2 int16, 4 float).
struct C3dParameter {
  std::string group;  ///< upper case, as in the file
  std::string name;   ///< upper case, as in the file
  int type = 0;
  std::vector<int> dims;  ///< empty for a scalar
  std::vector<double> numbers;  ///< byte, int16 and float values (int16 as signed), in file order
  std::string chars;            ///< char values (type -1), raw
  std::string description;
  std::size_t offset = 0;  ///< byte offset of the parameter's record in the file

  /// Char arrays as strings: dims[0] characters each (trailing blanks and NULs trimmed); a
  /// 1-dimensional or scalar char parameter gives one string.
  std::vector<std::string> strings() const;
  /// Element count (product of dims, 1 for a scalar).
  std::size_t count() const;
};

struct C3d {
  std::string file;
  C3dProcessor processor = C3dProcessor::kIntel;
  C3dStorage storage = C3dStorage::kInt16;

  int points = 0;            ///< 3D points per frame (header word 2 = POINT:USED)
  int analog_per_frame = 0;  ///< analog samples per 3D frame, all channels (header word 3)
  int first_frame = 1;       ///< header word 4 (1-based, as the file numbers frames)
  int last_frame = 0;        ///< header word 5
  double rate = 0.0;         ///< frames per second (POINT:RATE, else the header)
  double scale = 1.0;        ///< POINT:SCALE, else the header (negative: float storage)
  int data_start_block = 0;  ///< 1-based 512-byte block of the first frame (POINT:DATA_START, else header)
  std::string units;         ///< POINT:UNITS, trimmed ("" if absent)
  /// One per point: POINT:LABELS (then LABELS2, ...) trimmed; "P<n>" (1-based) where the file has none.
  std::vector<std::string> labels;
  std::vector<C3dParameter> parameters;

  /// Frames the header declares (last − first + 1).
  int framesDeclared() const { return last_frame - first_frame + 1; }
  int frames_present = 0;  ///< whole frames read (== framesDeclared() unless truncated)
  bool truncated = false;  ///< the data stops before the declared last frame

  /// frames_present × points × 3 coordinates in the file's units (NaN where invalid).
  std::vector<float> xyz;
  /// frames_present × points residuals in the file's units; negative where the sample is invalid.
  std::vector<float> residual;

  /// Analog channels (ANALOG:USED; 0 when the file has no analog data) and samples of each channel per
  /// 3D frame (analog_per_frame / analog_channels).
  int analog_channels = 0;
  int analog_subframes = 0;
  double analog_rate = 0.0;  ///< samples per second of one channel (ANALOG:RATE, else rate × subframes)
  /// One per channel: ANALOG:LABELS trimmed ("A<n>", 1-based, where the file has none), ANALOG:UNITS ("").
  std::vector<std::string> analog_labels;
  std::vector<std::string> analog_units;
  /// Per channel: value = (stored − analog_offset) × analog_scale × analog_gen_scale (C3D user guide).
  std::vector<double> analog_scale;
  std::vector<double> analog_offset;
  double analog_gen_scale = 1.0;
  /// Stored analog words, frames_present × analog_subframes × analog_channels, in file order (subframe
  /// major, channel minor): int16 as signed, or unsigned with ANALOG:FORMAT "UNSIGNED"; floats as read.
  std::vector<float> analog_stored;

  /// Analog samples per channel present (frames_present × analog_subframes).
  int analogSamples() const { return frames_present * analog_subframes; }
  /// The scaled value of `channel` (0-based) at analog sample `sample` (0-based, < analogSamples()).
  double analog(int sample, int channel) const;
  /// Index of the analog channel labelled `label` (case-sensitive, trimmed), or -1.
  int analogIndex(std::string_view label) const;

  /// The parameter GROUP:NAME (case-insensitive), or nullptr.
  const C3dParameter* find(std::string_view group, std::string_view name) const;
  /// Point `index` of 0-based frame `frame` (< frames_present), or nullopt if the sample is invalid
  /// (negative residual word, or a non-finite float coordinate).
  std::optional<std::array<double, 3>> point(int frame, int index) const;
  /// Index of the point labelled `label` (case-sensitive, trimmed), or -1.
  int pointIndex(std::string_view label) const;
};

/// Parses a whole C3D file held in memory; `file` names it in errors.
/// \throws C3dError for a malformed file.
C3d parseC3d(std::string_view bytes, const std::string& file);
/// Reads and parses `path`. \throws C3dError (offset 0) if it cannot be read, or for a malformed file.
C3d readC3dFile(const std::string& path);

/// Resolves a frame index against frames_present: [0, n) as is, negative from the end (-1 = last).
/// \throws std::out_of_range naming the index and the range.
int resolveC3dFrame(const C3d& c3d, long long frame);

}  // namespace mannequin::mocap
