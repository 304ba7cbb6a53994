#pragma once
// Configuration overrides: a YAML mapping laid over a configuration file, key by
// key. The nodelets turn their `config` ROS parameters into such a mapping, so
// that a ROS parameter overrides the same key of the YAML file and is validated
// by the same loaders, with the same errors naming the key.

#include <string>
#include <vector>

namespace alvio {

/// `base` (YAML text) with every leaf of `overlay` (YAML text of a mapping) replacing or
/// adding the same dotted key. Nested mappings merge; anything else replaces. Throws
/// alvio::Error naming `base_name` or `overlay_name` on a syntax error, or when an overlay
/// key would descend into a value that is not a mapping.
std::string overlayYaml(const std::string& base, const std::string& base_name,
                        const std::string& overlay, const std::string& overlay_name);

/// Dotted paths of the leaves (non-mapping values) of a YAML mapping text.
std::vector<std::string> yamlLeafKeys(const std::string& text);

/// A YAML mapping text from one dotted assignment, "estimator.window_size=8" ->
/// "estimator:\n  window_size: 8\n". Throws alvio::Error on a missing '=' or empty key.
std::string assignmentToYaml(const std::string& assignment);

/// A comma-separated list of assignments split at the commas that separate them, not at
/// those inside a flow sequence or mapping or a quoted value:
/// "a=1,camera.resolution=[640, 480]" -> {"a=1", "camera.resolution=[640, 480]"}.
/// Throws alvio::Error on unbalanced brackets or quotes.
std::vector<std::string> splitAssignments(const std::string& list);

/// The contents of a text file; throws alvio::Error naming it when it cannot be read.
std::string readTextFile(const std::string& path);

/// A configuration file's text with its `base:` resolved: a file may name another
/// configuration (a path relative to its own folder) whose keys it overrides one by one, so
/// that a robot's or a sensor's file holds only what differs. Bases may have bases. Throws
/// alvio::Error naming the file and key on a missing base or a cycle.
std::string readConfigText(const std::string& path);

}  // namespace alvio
