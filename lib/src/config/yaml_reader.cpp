#include "alvio/config/yaml_reader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"

namespace alvio {
namespace {

std::vector<std::string> splitKey(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

// OpenCV writes "%YAML:1.0", which is not a valid YAML directive.
std::string stripOpenCvHeader(const std::string& text) {
  if (text.rfind("%YAML:", 0) == 0) {
    const auto eol = text.find('\n');
    return eol == std::string::npos ? std::string() : "#" + text.substr(0, eol) + text.substr(eol);
  }
  return text;
}

void collectKeys(const YAML::Node& node, const std::string& prefix, std::vector<std::string>* out) {
  if (!node.IsMap()) {
    out->push_back(prefix);
    return;
  }
  for (const auto& kv : node) {
    // A complex key ("? [a, b]: x") is not a scalar: name it by its YAML text instead of
    // throwing from here (found by fuzz_config; unknownKeys runs in noexcept paths).
    const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : YAML::Dump(kv.first);
    collectKeys(kv.second, prefix.empty() ? name : prefix + "." + name, out);
  }
}

}  // namespace

YamlReader::YamlReader(const std::string& path) : path_(path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open config file '" + path + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  try {
    root_ = std::make_unique<YAML::Node>(YAML::Load(stripOpenCvHeader(buffer.str())));
  } catch (const YAML::Exception& e) {
    throw Error(path + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " +
                e.msg);
  }
  if (!root_->IsMap() && !root_->IsNull())
    throw Error(path + ": expected a mapping of keys at the top level");
}

YamlReader YamlReader::fromString(const std::string& text, const std::string& name) {
  YamlReader reader;
  reader.path_ = name;
  try {
    reader.root_ = std::make_unique<YAML::Node>(YAML::Load(stripOpenCvHeader(text)));
  } catch (const YAML::Exception& e) {
    throw Error(name + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " +
                e.msg);
  }
  return reader;
}

YamlReader::~YamlReader() = default;
YamlReader::YamlReader(YamlReader&&) noexcept = default;

std::string YamlReader::where(const std::string& key) const {
  return path_ + ": key '" + key + "'";
}

std::optional<YAML::Node> YamlReader::find(const std::string& key, bool mark_used) const {
  if (mark_used) used_.insert(key);
  // reset() rebinds; operator= would overwrite the node's content in the tree.
  YAML::Node node;
  node.reset(*root_);
  for (const auto& part : splitKey(key)) {
    if (!node.IsMap()) return std::nullopt;
    const YAML::Node& parent = node;
    YAML::Node child = parent[part];
    if (!child.IsDefined() || child.IsNull()) return std::nullopt;
    node.reset(child);
  }
  return node;
}

YAML::Node YamlReader::require(const std::string& key) const {
  auto node = find(key);
  if (!node) throw Error(where(key) + " is missing");
  return *node;
}

bool YamlReader::has(const std::string& key) const {
  return find(key, false).has_value();
}

namespace {
template <typename T>
T convert(const YAML::Node& node, const std::string& where, const char* type_name) {
  if (!node.IsScalar()) throw Error(where + " must be a " + type_name + " scalar");
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(where + " must be a " + type_name + ", got '" + node.Scalar() + "'");
  }
}

double convertDouble(const YAML::Node& node, const std::string& where) {
  const double v = convert<double>(node, where, "number");
  if (!std::isfinite(v)) throw Error(where + " must be finite, got '" + node.Scalar() + "'");
  return v;
}
}  // namespace

double YamlReader::getDouble(const std::string& key) const {
  return convertDouble(require(key), where(key));
}
int YamlReader::getInt(const std::string& key) const {
  return convert<int>(require(key), where(key), "integer");
}
bool YamlReader::getBool(const std::string& key) const {
  return convert<bool>(require(key), where(key), "boolean (true/false)");
}
std::string YamlReader::getString(const std::string& key) const {
  return convert<std::string>(require(key), where(key), "string");
}

std::vector<double> YamlReader::getDoubles(const std::string& key, int expected_size) const {
  const YAML::Node node = require(key);
  if (!node.IsSequence()) throw Error(where(key) + " must be a list of numbers");
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i)
    values.push_back(convertDouble(node[i], where(key + "[" + std::to_string(i) + "]")));
  if (expected_size >= 0 && static_cast<int>(values.size()) != expected_size)
    throw Error(where(key) + " must have " + std::to_string(expected_size) + " values, got " +
                std::to_string(values.size()));
  return values;
}

double YamlReader::getDouble(const std::string& key, double fallback) const {
  auto node = find(key);
  return node ? convertDouble(*node, where(key)) : fallback;
}
int YamlReader::getInt(const std::string& key, int fallback) const {
  auto node = find(key);
  return node ? convert<int>(*node, where(key), "integer") : fallback;
}
bool YamlReader::getBool(const std::string& key, bool fallback) const {
  auto node = find(key);
  return node ? convert<bool>(*node, where(key), "boolean (true/false)") : fallback;
}
std::string YamlReader::getString(const std::string& key, const std::string& fallback) const {
  auto node = find(key);
  return node ? convert<std::string>(*node, where(key), "string") : fallback;
}
std::vector<double> YamlReader::getDoubles(const std::string& key,
                                           const std::vector<double>& fallback) const {
  if (!find(key)) return fallback;
  return getDoubles(key);
}
Eigen::Vector3d YamlReader::getPerAxis(const std::string& key,
                                       const Eigen::Vector3d& fallback) const {
  const std::optional<YAML::Node> node = find(key);
  if (!node) return fallback;
  if (node->IsSequence()) {
    const std::vector<double> v = getDoubles(key, 3);
    return {v[0], v[1], v[2]};
  }
  if (!node->IsScalar())
    throw Error(where(key) + " must be a number or a list of 3 numbers (x, y, z)");
  return Eigen::Vector3d::Constant(convertDouble(*node, where(key)));
}
std::string YamlReader::getChoice(const std::string& key, const std::string& fallback,
                                  const std::vector<std::string>& choices) const {
  const std::string value = getString(key, fallback);
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) return value;
  std::string list;
  for (std::size_t i = 0; i < choices.size(); ++i)
    list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
  throw Error(where(key) + " must be " + list + ", not '" + value + "'");
}

Eigen::Isometry3d YamlReader::getTransform(const std::string& key) const {
  const YAML::Node node = require(key);
  std::vector<double> data;
  if (node.IsMap()) {
    const int rows = getInt(key + ".rows", 4);
    const int cols = getInt(key + ".cols", 4);
    if (rows != 4 || cols != 4) throw Error(where(key) + " must be a 4x4 matrix");
    data = getDoubles(key + ".data", 16);
  } else if (node.IsSequence() && node.size() == 4 && node[0].IsSequence()) {
    for (std::size_t r = 0; r < 4; ++r) {
      if (!node[r].IsSequence() || node[r].size() != 4)
        throw Error(where(key) + " must be a 4x4 nested list");
      for (std::size_t c = 0; c < 4; ++c)
        data.push_back(convertDouble(
            node[r][c], where(key + "[" + std::to_string(r) + "][" + std::to_string(c) + "]")));
    }
  } else {
    data = getDoubles(key, 16);
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = data[4 * r + c];
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if (std::abs(R.determinant()) < 1e-6)
    throw Error(where(key) + " is not invertible: its rotation block is singular (det = " +
                std::to_string(R.determinant()) + ")");
  const double orth_err = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (orth_err > 1e-3 || R.determinant() < 0.5) {
    std::ostringstream os;
    os << where(key) << " has a rotation block that is not a rotation (|R^T R - I| = " << orth_err
       << ", det = " << R.determinant() << ")";
    throw Error(os.str());
  }
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    throw Error(where(key) + " must have a last row of [0, 0, 0, 1]");
  // Re-orthonormalise: calibration files store ~10 digits.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

void YamlReader::markKnown(const std::string& key) const {
  used_.insert(key);
}

std::vector<std::string> YamlReader::unknownKeys() const {
  std::vector<std::string> all;
  collectKeys(*root_, "", &all);
  std::vector<std::string> unknown;
  for (const auto& key : all) {
    if (key.empty()) continue;
    bool known = false;
    // A key is known when it or one of its parents was asked for.
    for (std::string k = key;; k = k.substr(0, k.rfind('.'))) {
      if (used_.count(k)) {
        known = true;
        break;
      }
      if (k.find('.') == std::string::npos) break;
    }
    if (!known) unknown.push_back(key);
  }
  return unknown;
}

void YamlReader::warnUnknownKeys() const {
  for (const auto& key : unknownKeys())
    logWarn(path_, ": unknown key '", key, "' is ignored (misspelt?)");
}

}  // namespace alvio
