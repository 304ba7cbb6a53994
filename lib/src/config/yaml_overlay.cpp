#include "alvio/config/yaml_overlay.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "alvio/common/error.h"

namespace alvio {

namespace {

// OpenCV's "%YAML:1.0" first line is not valid YAML (as in YamlReader).
std::string withoutOpenCvHeader(const std::string& text) {
  if (text.rfind("%YAML:", 0) != 0) return text;
  const auto eol = text.find('\n');
  return eol == std::string::npos ? std::string() : text.substr(eol);
}

YAML::Node parse(const std::string& text, const std::string& name) {
  try {
    return YAML::Load(withoutOpenCvHeader(text));
  } catch (const YAML::Exception& e) {
    throw Error(name + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " +
                e.msg);
  }
}

void overlay(YAML::Node base, const YAML::Node& over, const std::string& prefix,
             const std::string& overlay_name) {
  for (const auto& kv : over) {
    const std::string key = kv.first.as<std::string>();
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (kv.second.IsMap()) {
      if (base[key] && !base[key].IsMap() && !base[key].IsNull())
        throw Error(overlay_name + ": key '" + path +
                    "' is a group of keys, but the configuration file has a single value there");
      if (!base[key] || base[key].IsNull()) base[key] = YAML::Node(YAML::NodeType::Map);
      overlay(base[key], kv.second, path, overlay_name);
    } else {
      base[key] = kv.second;
    }
  }
}

void leaves(const YAML::Node& node, const std::string& prefix, std::vector<std::string>* out) {
  if (!node.IsMap()) {
    if (!prefix.empty()) out->push_back(prefix);
    return;
  }
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    leaves(kv.second, prefix.empty() ? key : prefix + "." + key, out);
  }
}

}  // namespace

std::string overlayYaml(const std::string& base, const std::string& base_name,
                        const std::string& overlay_text, const std::string& overlay_name) {
  YAML::Node root = parse(base, base_name);
  const YAML::Node over = parse(overlay_text, overlay_name);
  if (over.IsNull()) return base;
  if (!over.IsMap()) throw Error(overlay_name + ": expected a mapping of keys");
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw Error(base_name + ": expected a mapping of keys at the top level");
  overlay(root, over, "", overlay_name);
  YAML::Emitter out;
  out << root;
  return out.c_str();
}

std::vector<std::string> yamlLeafKeys(const std::string& text) {
  std::vector<std::string> out;
  leaves(parse(text, "overrides"), "", &out);
  return out;
}

std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read '" + path + "'");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

namespace {
std::string readConfigText(const std::string& path, int depth) {
  const std::string text = readTextFile(path);
  YAML::Node root = parse(text, path);
  if (!root.IsMap() || !root["base"]) return text;
  const YAML::Node base = root["base"];
  if (!base.IsScalar() || base.as<std::string>().empty())
    throw Error(path + ": key 'base' must name a configuration file");
  if (depth >= 8) throw Error(path + ": key 'base': more than 8 files deep (a cycle?)");
  std::filesystem::path base_path = base.as<std::string>();
  if (base_path.is_relative()) base_path = std::filesystem::path(path).parent_path() / base_path;
  std::string base_text;
  try {
    base_text = readConfigText(base_path.string(), depth + 1);
  } catch (const Error& e) {
    throw Error(path + ": key 'base': " + e.what());
  }
  root.remove("base");
  YAML::Emitter out;
  out << root;
  return overlayYaml(base_text, base_path.string(), out.c_str(), path);
}
}  // namespace

std::string readConfigText(const std::string& path) {
  return readConfigText(path, 0);
}

std::vector<std::string> splitAssignments(const std::string& list) {
  std::vector<std::string> out;
  std::string current;
  int depth = 0;
  char quote = 0;
  for (const char c : list) {
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      if (--depth < 0) break;
    } else if (c == ',' && depth == 0) {
      out.push_back(current);
      current.clear();
      continue;
    }
    current += c;
  }
  if (depth != 0 || quote)
    throw Error("configuration overrides '" + list + "': unbalanced " +
                (quote ? std::string("quote") : std::string("brackets")));
  out.push_back(current);
  return out;
}

std::string assignmentToYaml(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("configuration override '" + assignment + "' is not key=value");
  const std::string key = assignment.substr(0, eq);
  std::string text;
  std::string indent;
  std::size_t start = 0;
  for (;;) {
    const auto dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? dot : dot - start);
    if (part.empty()) throw Error("configuration override '" + assignment + "': empty key part");
    text += indent + part + ":";
    if (dot == std::string::npos) break;
    text += "\n";
    indent += "  ";
    start = dot + 1;
  }
  // Quote nothing: the value is parsed as YAML, so "true", "8" and "[1, 2]" keep their types.
  return text + " " + assignment.substr(eq + 1) + "\n";
}

}  // namespace alvio
