#include "nodelet_config.h"

#include <xmlrpcpp/XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>

#include "alvio/common/error.h"
#include "alvio/config/yaml_overlay.h"

namespace alvio_ros {

namespace {

using XmlRpc::XmlRpcValue;

void emit(YAML::Emitter& out, XmlRpcValue& v, const std::string& where) {
  switch (v.getType()) {
    case XmlRpcValue::TypeBoolean:
      out << static_cast<bool>(v);
      break;
    case XmlRpcValue::TypeInt:
      out << static_cast<int>(v);
      break;
    case XmlRpcValue::TypeDouble:
      out << YAML::Precision(17) << static_cast<double>(v);
      break;
    case XmlRpcValue::TypeString:
      out << static_cast<std::string>(v);
      break;
    case XmlRpcValue::TypeArray:
      out << YAML::Flow << YAML::BeginSeq;
      for (int i = 0; i < v.size(); ++i) emit(out, v[i], where);
      out << YAML::EndSeq;
      break;
    case XmlRpcValue::TypeStruct:
      out << YAML::BeginMap;
      for (auto& kv : v) {
        out << YAML::Key << kv.first << YAML::Value;
        emit(out, kv.second, where + "/" + kv.first);
      }
      out << YAML::EndMap;
      break;
    default:
      throw alvio::Error("parameter '" + where + "' has a type that a configuration cannot hold");
  }
}

// The resolved name of a parameter in the private namespace or else in the nodelet's
// namespace, "" when in neither. (Not searchParam: it would reach unrelated parameters of
// the same name further up.)
std::string search(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                   const std::string& name) {
  if (private_nh.hasParam(name)) return private_nh.resolveName(name);
  if (nh.hasParam(name)) return nh.resolveName(name);
  return std::string();
}

std::string resolved(const ros::NodeHandle& nh, const std::string& name) {
  return nh.resolveName(name);
}

// The parameter's value, or false when unset; throws when set to another type.
bool fetch(const ros::NodeHandle& nh, const std::string& name, XmlRpcValue* value,
           std::initializer_list<XmlRpcValue::Type> types, const char* type_name) {
  if (!nh.getParam(name, *value)) return false;
  if (std::find(types.begin(), types.end(), value->getType()) == types.end())
    throw alvio::Error("parameter '" + resolved(nh, name) + "' must be " + type_name + ", got " +
                       value->toXml());
  return true;
}

}  // namespace

NodeletConfig::NodeletConfig(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) {
  const std::string file_param = search(nh, private_nh, "config_file");
  file_ = file_param.empty() ? alvio::Config::defaultPath()
                             : param(private_nh, file_param, std::string());
  if (file_.empty())
    throw alvio::Error("parameter '" + file_param + "' is empty: set it to a YAML configuration");
  std::string text;
  try {
    text = alvio::readConfigText(file_);
  } catch (const alvio::Error& e) {
    throw alvio::Error(std::string(e.what()) + " (parameter '" +
                       (file_param.empty() ? "config_file" : file_param) + "')");
  }

  overrides_param_ = search(nh, private_nh, "config");
  std::string name = file_;
  if (!overrides_param_.empty()) {
    XmlRpcValue tree;
    private_nh.getParam(overrides_param_, tree);
    if (tree.getType() != XmlRpcValue::TypeStruct)
      throw alvio::Error("parameter '" + overrides_param_ +
                         "' must be a dictionary of configuration keys (e.g. "
                         "config/estimator/window_size)");
    YAML::Emitter out;
    emit(out, tree, overrides_param_);
    const std::string overrides = out.c_str();
    override_keys_ = alvio::yamlLeafKeys(overrides);
    name = file_ + " with ROS parameters " + overrides_param_;
    text = alvio::overlayYaml(text, file_, overrides, "ROS parameters " + overrides_param_);
  }
  yaml_ = std::make_unique<alvio::YamlReader>(alvio::YamlReader::fromString(text, name));
  config_ = alvio::Config::load(*yaml_);
}

void NodeletConfig::rejectUnusedOverrides() const {
  const auto unknown = yaml_->unknownKeys();
  std::string bad;
  for (const auto& key : override_keys_)
    if (std::find(unknown.begin(), unknown.end(), key) != unknown.end()) {
      std::string name = key;  // as the parameter is spelt
      std::replace(name.begin(), name.end(), '.', '/');
      bad += (bad.empty() ? "" : ", ") + overrides_param_ + "/" + name;
    }
  if (!bad.empty())
    throw alvio::Error("unknown configuration key(s) in ROS parameters: " + bad + " (misspelt?)");
}

std::string NodeletConfig::describe() const {
  if (override_keys_.empty()) return file_;
  return file_ + " + " + std::to_string(override_keys_.size()) + " override(s) from " +
         overrides_param_;
}

bool param(const ros::NodeHandle& nh, const std::string& name, bool fallback) {
  XmlRpcValue v;
  return fetch(nh, name, &v, {XmlRpcValue::TypeBoolean}, "a boolean") ? static_cast<bool>(v)
                                                                      : fallback;
}

int param(const ros::NodeHandle& nh, const std::string& name, int fallback) {
  XmlRpcValue v;
  return fetch(nh, name, &v, {XmlRpcValue::TypeInt}, "an integer") ? static_cast<int>(v) : fallback;
}

double param(const ros::NodeHandle& nh, const std::string& name, double fallback) {
  XmlRpcValue v;
  if (!fetch(nh, name, &v, {XmlRpcValue::TypeDouble, XmlRpcValue::TypeInt}, "a number"))
    return fallback;
  return v.getType() == XmlRpcValue::TypeInt ? static_cast<int>(v) : static_cast<double>(v);
}

std::string param(const ros::NodeHandle& nh, const std::string& name, const std::string& fallback) {
  XmlRpcValue v;
  return fetch(nh, name, &v, {XmlRpcValue::TypeString}, "a string") ? static_cast<std::string>(v)
                                                                    : fallback;
}

void requireParam(bool ok, const ros::NodeHandle& nh, const std::string& name,
                  const std::string& what) {
  if (!ok) throw alvio::Error("parameter '" + resolved(nh, name) + "' " + what);
}

}  // namespace alvio_ros
