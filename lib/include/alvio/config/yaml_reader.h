#pragma once
// Typed access to a YAML file by dotted key path ("camera.intrinsics"), with
// errors that name the file and key, and a record of which keys were read so
// that unknown (probably misspelt) keys can be reported.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace alvio {

class YamlReader {
 public:
  /// Parse `path`. OpenCV-style "%YAML:1.0" headers (as in EuRoC sensor.yaml) are accepted.
  explicit YamlReader(const std::string& path);
  /// Parse YAML held in memory; `name` stands for the file in messages.
  static YamlReader fromString(const std::string& text, const std::string& name);
  ~YamlReader();
  YamlReader(YamlReader&&) noexcept;

  const std::string& path() const { return path_; }
  bool has(const std::string& key) const;

  // Required keys: throw alvio::Error naming file and key when missing or malformed.
  double getDouble(const std::string& key) const;
  int getInt(const std::string& key) const;
  bool getBool(const std::string& key) const;
  std::string getString(const std::string& key) const;
  std::vector<double> getDoubles(const std::string& key, int expected_size = -1) const;
  /// A 4x4 rigid transform, given as {rows: 4, cols: 4, data: [16]}, a flat list of
  /// 16 numbers or a nested 4x4 list. Rejects a rotation block that is not orthonormal.
  Eigen::Isometry3d getTransform(const std::string& key) const;

  // Optional keys: the fallback when absent, an error when present but malformed.
  double getDouble(const std::string& key, double fallback) const;
  int getInt(const std::string& key, int fallback) const;
  bool getBool(const std::string& key, bool fallback) const;
  std::string getString(const std::string& key, const std::string& fallback) const;
  std::vector<double> getDoubles(const std::string& key, const std::vector<double>& fallback) const;
  /// Per-axis values (x, y, z): one number for all three, or a list of three.
  Eigen::Vector3d getPerAxis(const std::string& key, const Eigen::Vector3d& fallback) const;
  /// One word out of `choices`; anything else throws "<where> must be a, b or c, not 'x'".
  std::string getChoice(const std::string& key, const std::string& fallback,
                        const std::vector<std::string>& choices) const;

  /// Mark a key (and everything under it) as known without reading it.
  void markKnown(const std::string& key) const;
  /// Keys present in the file that nothing read or marked, as dotted paths.
  std::vector<std::string> unknownKeys() const;
  /// Log a warning per unknown key.
  void warnUnknownKeys() const;

  /// "file: key 'a.b'" prefix used in every message.
  std::string where(const std::string& key) const;

 private:
  YamlReader() = default;
  std::optional<YAML::Node> find(const std::string& key, bool mark_used = true) const;
  YAML::Node require(const std::string& key) const;

  std::string path_;
  std::unique_ptr<YAML::Node> root_;
  mutable std::set<std::string> used_;
};

}  // namespace alvio
