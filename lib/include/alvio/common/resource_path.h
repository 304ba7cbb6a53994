#pragma once
// Locating files that ship with the package (config/, scripts/) both in a
// source checkout and in an installed catkin package.

#include <string>

namespace alvio {

/// Path of `relative` (e.g. "config/euroc.yaml") under $ALVIO_ROOT, the source tree
/// this library was built from, or the installed share/alvio. Throws alvio::Error if absent.
std::string findPackageFile(const std::string& relative);

}  // namespace alvio
