#pragma once
// Degrees to radians: configuration keys are in degrees, the geometry in radians.

#include <cmath>

namespace alvio {

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace alvio
