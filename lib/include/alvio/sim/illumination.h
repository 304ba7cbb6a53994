#pragma once
// Global illumination changes over time: a constant dim factor, flicker (mains
// lamps or clouds), and periodic dark segments (lights switched off), with
// smooth transitions so that they look like light, not like cuts.

#include <string>

namespace alvio::sim {

struct IlluminationOptions {
  double gain = 1.0;               ///< constant factor on all light
  double flicker_amplitude = 0.0;  ///< relative, e.g. 0.15 = +-15 %
  double flicker_hz = 0.0;
  double dark_period_s = 0.0;    ///< a dark segment starts every period (0 = never)
  double dark_duration_s = 0.0;  ///< how long it lasts
  double dark_gain = 0.25;       ///< factor during a dark segment
  double dark_first_s = 10.0;    ///< start of the first dark segment after the sequence start
  double transition_s = 0.4;     ///< fade in/out of a dark segment

  /// Multiplier on the image at `t_rel` seconds after the sequence start.
  double factorAt(double t_rel) const;
  bool isConstant() const {
    return flicker_amplitude == 0.0 && (dark_period_s <= 0 || dark_duration_s <= 0);
  }
  std::string describe() const;
};

/// Presets "normal", "dim" (gain 0.35), "flicker", "dark" (dark segments), or a
/// comma-separated list of key=value (gain, flicker, flicker_hz, dark_period,
/// dark_duration, dark_gain, dark_first, transition), e.g. "gain=0.5,flicker=0.1".
IlluminationOptions parseIllumination(const std::string& text);

}  // namespace alvio::sim
