#pragma once
// Command-line parsing for the tools: "--name value" and "--flag" options with
// defaults, help text, and errors that name the bad option.

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace alvio {

class ArgParser {
 public:
  ArgParser(std::string program, std::string summary);

  /// Declare an option taking a value; `fallback` empty + required=true makes it mandatory.
  void option(const std::string& name, const std::string& help, const std::string& fallback = "",
              bool required = false);
  /// Declare an option that may be given several times; get() joins the values with ','.
  void listOption(const std::string& name, const std::string& help);
  /// Declare a boolean flag (no value).
  void flag(const std::string& name, const std::string& help);

  /// Parse argv. Prints help and returns false on --help; throws alvio::Error on bad input.
  bool parse(int argc, char** argv);

  std::string get(const std::string& name) const;
  double getDouble(const std::string& name) const;
  int getInt(const std::string& name) const;
  bool isSet(const std::string& name) const;  ///< flag given, or option given explicitly
  const std::vector<std::string>& positional() const { return positional_; }
  std::string help() const;

 private:
  struct Spec {
    std::string help, fallback;
    bool is_flag = false, required = false, is_list = false;
  };
  std::string program_, summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

}  // namespace alvio
