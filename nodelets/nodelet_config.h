#pragma once
// Parameters of the alvio nodelets.
//
// The configuration is the offline runner's YAML file, named by the `config_file`
// parameter, with the `config` parameter tree laid over it key by key:
// `config/estimator/window_size` overrides `estimator.window_size`. Both are
// looked up in the nodelet's private namespace, then in its namespace, so a
// launch file can set them once for all the nodelets of a group. The
// merged YAML goes through the same loaders as the file, so a bad value is an
// alvio::Error naming the key; an override key that nothing reads (misspelt) is
// an error too.
//
// Plain ROS parameters (frame names, queue sizes, topics, output_dir) are read
// with param(), which rejects a value of the wrong type, naming the parameter.

#include <ros/node_handle.h>

#include <memory>
#include <string>
#include <vector>

#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"

namespace alvio_ros {

class NodeletConfig {
 public:
  /// Reads `config_file` (default: the bundled config/euroc.yaml) and the `config`
  /// overrides. Throws alvio::Error.
  NodeletConfig(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);

  /// The merged YAML, for loaders beyond Config (MappingOptions).
  const alvio::YamlReader& yaml() const { return *yaml_; }
  /// Config::load of the merged YAML.
  const alvio::Config& config() const { return config_; }
  /// Throws alvio::Error naming every override key that no loader has read. Call after the
  /// nodelet's loaders have run.
  void rejectUnusedOverrides() const;
  /// "<file>" or "<file> + N overrides from <param>", for the start-up message.
  std::string describe() const;

 private:
  std::string file_, overrides_param_;
  std::vector<std::string> override_keys_;
  std::unique_ptr<alvio::YamlReader> yaml_;
  alvio::Config config_;
};

/// A ROS parameter of `nh` (pass the private node handle for private parameters), or
/// `fallback` when it is not set.
/// Throws alvio::Error naming the parameter when it is set to a value of another type.
bool param(const ros::NodeHandle& nh, const std::string& name, bool fallback);
int param(const ros::NodeHandle& nh, const std::string& name, int fallback);
double param(const ros::NodeHandle& nh, const std::string& name, double fallback);
std::string param(const ros::NodeHandle& nh, const std::string& name, const std::string& fallback);
inline std::string param(const ros::NodeHandle& nh, const std::string& name, const char* fallback) {
  return param(nh, name, std::string(fallback));
}

/// Throws alvio::Error naming the parameter unless `ok`.
void requireParam(bool ok, const ros::NodeHandle& nh, const std::string& name,
                  const std::string& what);

}  // namespace alvio_ros
