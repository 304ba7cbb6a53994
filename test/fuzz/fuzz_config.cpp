// libFuzzer target: the YAML configuration loader (YamlReader + Config::load, and the
// MappingOptions the offline runner reads). Any input must either load or throw
// alvio::Error; a loaded config must hold the values validation promises.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const bool quiet = [] {
    alvio::setLogSink([](alvio::LogLevel, const std::string&) {});  // unknown-key warnings
    return true;
  }();
  (void)quiet;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto yaml = alvio::YamlReader::fromString(text, "fuzz.yaml");
    const alvio::Config c = alvio::Config::load(yaml);
    // What validation guarantees to the rest of the pipeline.
    if (c.camera.width <= 0 || c.camera.height <= 0 || c.camera.intrinsics.size() != 4 ||
        !(c.camera.intrinsics[0] > 0) || !(c.imu.gyroscope_noise_density > 0) ||
        !(c.imu.accelerometer_noise_density > 0) || !c.camera.T_b_c.matrix().allFinite() ||
        std::abs(c.camera.T_b_c.linear().determinant() - 1.0) > 1e-6)
      std::abort();
    (void)yaml.unknownKeys();
  } catch (const alvio::Error&) {
    // A clear rejection is the expected outcome for most inputs.
  }
  return 0;
}
