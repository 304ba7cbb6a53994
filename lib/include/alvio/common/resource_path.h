#pragma once
// Locating files that ship with the package (config/, scripts/) both in a
// source checkout and in an installed catkin package.

#include <string>

namespace alvio {

/// Path of `relative` (e.g. "config/euroc.yaml"): under $ALVIO_ROOT if set, else in the
/// installed package of the running program (<prefix>/share/alvio, when it has the file),
/// else in the source tree this library was built from. Throws alvio::Error if absent.
std::string findPackageFile(const std::string& relative);

/// The same, for a program at `executable` (findPackageFile passes /proc/self/exe).
std::string findPackageFile(const std::string& relative, const std::string& executable);

}  // namespace alvio
