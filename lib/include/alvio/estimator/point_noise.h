#pragma once
// The noise of a point observation against its track's anchor observation.
//
// KLT moves a tracked point by a small error at every frame, so a track's position error
// grows like a random walk with its age (0.23 px one frame after detection, 1.1 px after 50
// on sim_MH_05; docs/benchmarks.md, twenty-first session). The reprojection factor compares
// a sighting with the anchor's ray, so its error grows with the time between the two: its
// variance is sigma^2 + drift * dt.

#include <cmath>

namespace alvio {

/// Standard deviation (px) of a sighting `dt_s` seconds after the anchor's, for white noise
/// `sigma_px` and a drift of `drift_px2_per_s` (variance per second). Exactly `sigma_px`
/// when the drift is 0.
inline double pointObservationSigmaPx(double sigma_px, double drift_px2_per_s, double dt_s) {
  if (drift_px2_per_s <= 0) return sigma_px;
  return std::sqrt(sigma_px * sigma_px + drift_px2_per_s * std::abs(dt_s));
}

}  // namespace alvio
