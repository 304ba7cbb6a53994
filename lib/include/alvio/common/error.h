#pragma once
// One exception type for everything the core reports to a user: bad files, bad
// keys, bad data. The message always names the file, key or record at fault.

#include <stdexcept>
#include <string>

namespace alvio {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace alvio
