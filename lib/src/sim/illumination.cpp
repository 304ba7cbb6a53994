#include "alvio/sim/illumination.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "alvio/common/error.h"

namespace alvio::sim {

double IlluminationOptions::factorAt(double t) const {
  double f = gain;
  if (flicker_amplitude != 0.0 && flicker_hz > 0) {
    // Two incommensurate tones so that the flicker does not look periodic.
    f *= 1.0 + flicker_amplitude * (0.7 * std::sin(2 * M_PI * flicker_hz * t) +
                                    0.3 * std::sin(2 * M_PI * flicker_hz * 0.37 * t + 1.3));
  }
  if (dark_period_s > 0 && dark_duration_s > 0) {
    // Weight of being inside the segment [0, D] of local time s, with smooth edges.
    const double tr = std::max(transition_s, 1e-6);
    auto inside = [&](double s) {
      const double w = std::clamp((s + tr / 2) / tr, 0.0, 1.0) *
                       std::clamp((dark_duration_s - s + tr / 2) / tr, 0.0, 1.0);
      return w * w * (3 - 2 * w);
    };
    const double k = std::floor((t - dark_first_s) / dark_period_s);
    double w = 0;
    for (double j = std::max(0.0, k - 1); j <= k + 1; ++j)
      w = std::max(w, inside(t - dark_first_s - j * dark_period_s));
    f *= 1.0 - w * (1.0 - dark_gain);
  }
  return std::max(0.0, f);
}

std::string IlluminationOptions::describe() const {
  std::ostringstream os;
  os << "gain=" << gain << ",flicker=" << flicker_amplitude << ",flicker_hz=" << flicker_hz
     << ",dark_period=" << dark_period_s << ",dark_duration=" << dark_duration_s
     << ",dark_gain=" << dark_gain << ",dark_first=" << dark_first_s
     << ",transition=" << transition_s;
  return os.str();
}

IlluminationOptions parseIllumination(const std::string& text) {
  IlluminationOptions o;
  if (text.empty() || text == "normal") return o;
  if (text == "dim") {
    o.gain = 0.35;
    return o;
  }
  if (text == "flicker") {
    o.flicker_amplitude = 0.15;
    o.flicker_hz = 2.3;
    return o;
  }
  if (text == "dark") {
    o.dark_period_s = 25;
    o.dark_duration_s = 3;
    o.dark_gain = 0.2;
    return o;
  }
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw Error("--illumination: expected normal, dim, flicker, dark or key=value list, got '" +
                  item + "'");
    const std::string key = item.substr(0, eq);
    double v;
    try {
      std::size_t used = 0;
      v = std::stod(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw Error("--illumination: '" + key + "' needs a number, got '" + item.substr(eq + 1) +
                  "'");
    }
    if (key == "gain")
      o.gain = v;
    else if (key == "flicker")
      o.flicker_amplitude = v;
    else if (key == "flicker_hz")
      o.flicker_hz = v;
    else if (key == "dark_period")
      o.dark_period_s = v;
    else if (key == "dark_duration")
      o.dark_duration_s = v;
    else if (key == "dark_gain")
      o.dark_gain = v;
    else if (key == "dark_first")
      o.dark_first_s = v;
    else if (key == "transition")
      o.transition_s = v;
    else
      throw Error("--illumination: unknown key '" + key +
                  "' (gain, flicker, flicker_hz, dark_period, dark_duration, dark_gain, "
                  "dark_first, transition)");
  }
  if (o.gain < 0 || o.dark_gain < 0) throw Error("--illumination: gains must be >= 0");
  return o;
}

}  // namespace alvio::sim
