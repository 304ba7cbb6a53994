#pragma once
// Degrees and radians: configuration keys and reports are in degrees, the geometry in radians.

#include <cmath>

namespace alvio {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace alvio
