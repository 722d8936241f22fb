#pragma once
/// \file config.hpp
/// \brief The one YAML config reader of every library, service and tool: every error names FILE:LINE and
/// the field, unknown keys are refused with allowOnly().
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mannequin::core {

/// A bad config: what() is "FILE:LINE: field 'a.b': message".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A YAML node with where it came from, for error messages.
class ConfigNode {
 public:
  ConfigNode(YAML::Node node, std::string file, std::string path = {})
      : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

  /// Loads a file. \throws ConfigError (unreadable file, YAML syntax error with its line).
  static ConfigNode load(const std::string& path);
  /// Parses text; `source` names it in errors.
  static ConfigNode parse(const std::string& text, const std::string& source);

  bool has(const std::string& key) const;
  /// Child `key`. \throws ConfigError if absent.
  ConfigNode operator[](const std::string& key) const;
  /// Child `key`, or nullopt.
  std::optional<ConfigNode> find(const std::string& key) const;
  /// Elements of a sequence. \throws ConfigError if not a sequence.
  std::vector<ConfigNode> items() const;
  /// Keys of a map, in file order. \throws ConfigError if not a map.
  std::vector<std::string> keys() const;
  bool isSequence() const { return node_.IsSequence(); }
  bool isMap() const { return node_.IsMap(); }
  bool isScalar() const { return node_.IsScalar(); }

  std::string str() const;
  double num() const;            ///< finite number (YAML's .inf and .nan are refused)
  double positive() const;       ///< finite number > 0
  double nonNegative() const;    ///< finite number >= 0
  double numIn(double lo, double hi) const;  ///< finite number in [lo, hi]
  double numOrInfinity() const;  ///< a number or ±.inf (e.g. a free end stop); NaN refused
  long long integer() const;
  long long integerIn(long long lo, long long hi) const;
  bool boolean() const;
  Eigen::Vector3d vec3() const;    ///< [x, y, z]
  Eigen::VectorXd vector(int size = -1) const;  ///< a list of finite numbers, of `size` numbers if >= 0
  /// [roll, pitch, yaw] in degrees → R = Rz(yaw) Ry(pitch) Rx(roll).
  Eigen::Matrix3d rpyDeg() const;
  /// Index of the value in `options`. \throws ConfigError "expected a, b or c, got 'x'".
  std::size_t choice(const std::vector<std::string>& options) const;
  std::vector<std::string> strings() const;  ///< a scalar or a sequence of scalars

  /// Value of `key` or `fallback` when absent.
  std::string get(const std::string& key, const std::string& fallback) const;
  double get(const std::string& key, double fallback) const;
  long long get(const std::string& key, long long fallback) const;
  int get(const std::string& key, int fallback) const { return static_cast<int>(get(key, static_cast<long long>(fallback))); }
  bool get(const std::string& key, bool fallback) const;
  /// A number of `key` in [lo, hi] or `fallback`. \throws ConfigError out of range.
  double getIn(const std::string& key, double fallback, double lo, double hi) const;

  /// \throws ConfigError "FILE:LINE: field 'path': message".
  [[noreturn]] void fail(const std::string& message) const;
  /// Rejects keys not in `allowed` (typos in configs are errors, not silently ignored).
  void allowOnly(const std::vector<std::string>& allowed) const;
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  int line() const;
  /// "FILE:LINE", to name this entry in errors found after reading (see failAt).
  std::string where() const;

 private:
  YAML::Node node_;
  std::string file_;
  std::string path_;
};

/// \throws ConfigError "WHERE: field 'FIELD': MESSAGE" for a problem found after reading (a frame the
/// model lacks...); `where` is a ConfigNode::where() kept with the value.
[[noreturn]] void failAt(const std::string& where, const std::string& field, const std::string& message);

}  // namespace mannequin::core
