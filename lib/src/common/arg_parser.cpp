#include "alvio/common/arg_parser.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "alvio/common/error.h"

namespace alvio {

ArgParser::ArgParser(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

void ArgParser::option(const std::string& name, const std::string& help,
                       const std::string& fallback, bool required) {
  order_.push_back(name);
  specs_[name] = {help, fallback, false, required};
}

void ArgParser::listOption(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = {help, "", false, false, true};
}

void ArgParser::flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = {help, "", true, false};
}

std::string ArgParser::help() const {
  std::ostringstream os;
  os << "usage: " << program_ << " [options]\n" << summary_ << "\n\noptions:\n";
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    std::string left = "  --" + name + (s.is_flag ? "" : " VALUE");
    os << left << std::string(left.size() < 26 ? 26 - left.size() : 1, ' ') << s.help;
    if (s.required)
      os << " (required)";
    else if (!s.is_flag && !s.fallback.empty())
      os << " [default: " << s.fallback << "]";
    os << "\n";
  }
  return os.str();
}

bool ArgParser::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << help();
      return false;
    }
    if (arg.rfind("--", 0) != 0) {
      positional_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2), value;
    const auto eq = name.find('=');
    const bool has_inline = eq != std::string::npos;
    if (has_inline) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    const auto it = specs_.find(name);
    if (it == specs_.end()) throw Error("unknown option '--" + name + "' (see --help)");
    if (it->second.is_flag) {
      if (has_inline) throw Error("flag '--" + name + "' takes no value");
      values_[name] = "1";
      continue;
    }
    if (!has_inline) {
      if (i + 1 >= argc) throw Error("option '--" + name + "' needs a value");
      value = argv[++i];
    }
    // A repeated option replaces the earlier value, except a list option, which collects.
    const auto previous = values_.find(name);
    if (it->second.is_list && previous != values_.end())
      previous->second += "," + value;
    else
      values_[name] = value;
  }
  for (const auto& [name, spec] : specs_)
    if (spec.required && !values_.count(name))
      throw Error("missing required option '--" + name + "' (see --help)");
  return true;
}

std::string ArgParser::get(const std::string& name) const {
  const auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  return specs_.at(name).fallback;
}

bool ArgParser::isSet(const std::string& name) const {
  return values_.count(name) > 0;
}

double ArgParser::getDouble(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(d))
    throw Error("option '--" + name + "' needs a number, got '" + v + "'");
  return d;
}

int ArgParser::getInt(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const long d = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0')
    throw Error("option '--" + name + "' needs an integer, got '" + v + "'");
  return static_cast<int>(d);
}

}  // namespace alvio
