#include "alvio/lines/line_tracker_options.h"

#include <sstream>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {
namespace {
std::string keyPrefix(const std::string& prefix) {
  return prefix.empty() ? "" : prefix + ".";
}
std::string whereOf(const YamlReader& yaml, const std::string& prefix) {
  return prefix.empty() ? yaml.path() : yaml.path() + ": " + prefix;
}

// Throws "<where>.<key> must be <what>, got <value>" unless ok.
template <typename T>
void require(bool ok, const std::string& where, const std::string& key, const std::string& what,
             T value) {
  if (ok) return;
  std::ostringstream os;
  os << where << "." << key << " must be " << what << ", got " << value;
  throw Error(os.str());
}
}  // namespace

LineDetectorOptions LineDetectorOptions::load(const YamlReader& yaml, const std::string& prefix) {
  LineDetectorOptions o;
  const std::string p = keyPrefix(prefix);
  o.method = yaml.getString(p + "method", o.method);
  o.min_length_ratio = yaml.getDouble(p + "min_length_ratio", o.min_length_ratio);
  o.continuation_length_factor =
      yaml.getDouble(p + "continuation_length_factor", o.continuation_length_factor);
  o.max_lines = yaml.getInt(p + "max_lines", o.max_lines);
  o.max_detections = yaml.getInt(p + "max_detections", o.max_detections);
  o.lsd_scale = yaml.getDouble(p + "lsd_scale", o.lsd_scale);
  o.fld_scale = yaml.getDouble(p + "fld_scale", o.fld_scale);
  o.lsd_sigma_scale = yaml.getDouble(p + "lsd_sigma_scale", o.lsd_sigma_scale);
  o.lsd_pyramid_downscale = yaml.getBool(p + "lsd_pyramid_downscale", o.lsd_pyramid_downscale);
  o.lsd_refine = yaml.getBool(p + "lsd_refine", o.lsd_refine);
  o.lsd_quant = yaml.getDouble(p + "lsd_quant", o.lsd_quant);
  o.lsd_reference_brightness =
      yaml.getDouble(p + "lsd_reference_brightness", o.lsd_reference_brightness);
  o.lsd_min_quant_scale = yaml.getDouble(p + "lsd_min_quant_scale", o.lsd_min_quant_scale);
  o.border_margin_px = yaml.getInt(p + "border_margin_px", o.border_margin_px);
  o.refine_edges = yaml.getBool(p + "refine_edges", o.refine_edges);
  o.validate(whereOf(yaml, prefix));
  return o;
}

void LineDetectorOptions::validate(const std::string& where) const {
  if (method != "lsd" && method != "opencv_lsd" && method != "fld")
    throw Error(where + ": key 'method' must be lsd, opencv_lsd or fld, got '" + method + "'");
  if (lsd_refine && method != "opencv_lsd")
    throw Error(where + ": key 'lsd_refine' needs method opencv_lsd (got method '" + method + "')");
  if (lsd_pyramid_downscale && (method != "lsd" || lsd_scale != 0.5))
    throw Error(where + ": key 'lsd_pyramid_downscale' needs method lsd and lsd_scale 0.5");
  require(min_length_ratio > 0 && min_length_ratio < 1, where, "min_length_ratio", "in (0, 1)",
          min_length_ratio);
  require(continuation_length_factor > 0 && continuation_length_factor <= 1, where,
          "continuation_length_factor", "in (0, 1]", continuation_length_factor);
  require(max_lines > 0, where, "max_lines", "positive", max_lines);
  require(max_detections >= max_lines, where, "max_detections", ">= max_lines", max_detections);
  require(lsd_scale > 0 && lsd_scale <= 1, where, "lsd_scale", "in (0, 1]", lsd_scale);
  require(fld_scale > 0 && fld_scale <= 1, where, "fld_scale", "in (0, 1]", fld_scale);
  require(lsd_sigma_scale > 0, where, "lsd_sigma_scale", "positive", lsd_sigma_scale);
  require(lsd_quant > 0, where, "lsd_quant", "positive", lsd_quant);
  require(lsd_reference_brightness >= 0 && lsd_reference_brightness <= 255, where,
          "lsd_reference_brightness", "in [0, 255]", lsd_reference_brightness);
  require(lsd_min_quant_scale > 0 && lsd_min_quant_scale <= 1, where, "lsd_min_quant_scale",
          "in (0, 1]", lsd_min_quant_scale);
  require(border_margin_px >= 0, where, "border_margin_px", "non-negative", border_margin_px);
}

FlowLineTrackerOptions FlowLineTrackerOptions::load(const YamlReader& yaml,
                                                    const std::string& prefix) {
  FlowLineTrackerOptions o;
  const std::string p = keyPrefix(prefix);
  o.samples_per_line = yaml.getInt(p + "samples_per_line", o.samples_per_line);
  o.klt_window_px = yaml.getInt(p + "klt_window_px", o.klt_window_px);
  o.klt_pyramid_levels = yaml.getInt(p + "klt_pyramid_levels", o.klt_pyramid_levels);
  o.gyro_flow = yaml.getBool(p + "gyro_flow", o.gyro_flow);
  o.gyro_klt_levels = yaml.getInt(p + "gyro_klt_levels", o.gyro_klt_levels);
  o.klt_max_iterations = yaml.getInt(p + "klt_max_iterations", o.klt_max_iterations);
  o.klt_epsilon = yaml.getDouble(p + "klt_epsilon", o.klt_epsilon);
  o.knn = yaml.getInt(p + "knn", o.knn);
  o.max_angle_deg = yaml.getDouble(p + "max_angle_deg", o.max_angle_deg);
  o.max_line_distance_px = yaml.getDouble(p + "max_line_distance_px", o.max_line_distance_px);
  o.min_overlap_ratio = yaml.getDouble(p + "min_overlap_ratio", o.min_overlap_ratio);
  o.min_length_ratio = yaml.getDouble(p + "min_length_ratio", o.min_length_ratio);
  o.max_center_distance_px = yaml.getDouble(p + "max_center_distance_px", o.max_center_distance_px);
  o.detect_every = yaml.getInt(p + "detect_every", o.detect_every);
  o.validate(whereOf(yaml, prefix));
  return o;
}

void FlowLineTrackerOptions::validate(const std::string& where) const {
  require(samples_per_line >= 2, where, "samples_per_line", ">= 2", samples_per_line);
  require(klt_window_px >= 5 && klt_window_px % 2 == 1, where, "klt_window_px", "odd and >= 5",
          klt_window_px);
  require(klt_pyramid_levels >= 0, where, "klt_pyramid_levels", "non-negative", klt_pyramid_levels);
  require(gyro_klt_levels >= 0, where, "gyro_klt_levels", "non-negative", gyro_klt_levels);
  require(klt_max_iterations > 0, where, "klt_max_iterations", "positive", klt_max_iterations);
  require(klt_epsilon > 0, where, "klt_epsilon", "positive", klt_epsilon);
  require(knn >= 1, where, "knn", ">= 1", knn);
  require(max_angle_deg > 0 && max_angle_deg < 90, where, "max_angle_deg", "in (0, 90)",
          max_angle_deg);
  require(max_line_distance_px > 0, where, "max_line_distance_px", "positive",
          max_line_distance_px);
  require(min_overlap_ratio >= 0 && min_overlap_ratio <= 1, where, "min_overlap_ratio", "in [0, 1]",
          min_overlap_ratio);
  require(min_length_ratio > 0 && min_length_ratio <= 1, where, "min_length_ratio", "in (0, 1]",
          min_length_ratio);
  require(max_center_distance_px > 0, where, "max_center_distance_px", "positive",
          max_center_distance_px);
  require(detect_every >= 1, where, "detect_every", ">= 1", detect_every);
}

DescriptorLineTrackerOptions DescriptorLineTrackerOptions::load(const YamlReader& yaml,
                                                                const std::string& prefix) {
  DescriptorLineTrackerOptions o;
  const std::string p = keyPrefix(prefix);
  o.max_hamming_distance = yaml.getInt(p + "max_hamming_distance", o.max_hamming_distance);
  o.max_ratio = yaml.getDouble(p + "max_ratio", o.max_ratio);
  o.max_angle_deg = yaml.getDouble(p + "max_angle_deg", o.max_angle_deg);
  o.max_center_distance_px = yaml.getDouble(p + "max_center_distance_px", o.max_center_distance_px);
  o.validate(whereOf(yaml, prefix));
  return o;
}

void DescriptorLineTrackerOptions::validate(const std::string& where) const {
  require(max_hamming_distance > 0 && max_hamming_distance <= 256, where, "max_hamming_distance",
          "in (0, 256]", max_hamming_distance);
  require(max_ratio > 0 && max_ratio <= 1, where, "max_ratio", "in (0, 1]", max_ratio);
  require(max_angle_deg > 0 && max_angle_deg <= 180, where, "max_angle_deg", "in (0, 180]",
          max_angle_deg);
  require(max_center_distance_px > 0, where, "max_center_distance_px", "positive",
          max_center_distance_px);
}

LineTrackerOptions LineTrackerOptions::load(const YamlReader& yaml, const std::string& prefix) {
  LineTrackerOptions o;
  const std::string p = keyPrefix(prefix);
  o.tracker = yaml.getString(p + "tracker", o.tracker);
  o.own_thread = yaml.getBool(p + "own_thread", o.own_thread);
  o.map_edges = yaml.getBool(p + "map_edges", o.map_edges);
  o.detector = LineDetectorOptions::load(yaml, p + "detector");
  o.flow = FlowLineTrackerOptions::load(yaml, p + "flow");
  o.descriptor = DescriptorLineTrackerOptions::load(yaml, p + "descriptor");
  o.validate(whereOf(yaml, prefix));
  return o;
}

void LineTrackerOptions::validate(const std::string& where) const {
  if (tracker != "flow" && tracker != "descriptor")
    throw Error(where + ".tracker: unsupported '" + tracker + "' (expected flow or descriptor)");
  detector.validate(where + ".detector");
  flow.validate(where + ".flow");
  descriptor.validate(where + ".descriptor");
}

}  // namespace alvio
