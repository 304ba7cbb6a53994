#pragma once
// The readers under test take a file path: the fuzz input is handed over as an
// in-memory file (memfd), reached through /proc/self/fd, so no disk I/O per run.

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>

namespace alvio::fuzz {

class InputFile {
 public:
  InputFile() : fd_(memfd_create("alvio_fuzz_input", 0)) {
    if (fd_ < 0) std::abort();
  }
  /// Replace the content with `data` and return a path that opens it.
  std::string write(const uint8_t* data, std::size_t size) {
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, data, size, 0) != static_cast<ssize_t>(size))
      std::abort();
    return "/proc/self/fd/" + std::to_string(fd_);
  }

 private:
  int fd_;
};

}  // namespace alvio::fuzz
