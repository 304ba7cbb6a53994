#include "alvio/frontend/point_tracker_options.h"

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

PointTrackerOptions PointTrackerOptions::load(const YamlReader& yaml, const std::string& prefix) {
  PointTrackerOptions o;
  const std::string p = prefix + ".";
  o.max_features = yaml.getInt(p + "max_features", o.max_features);
  o.min_distance_px = yaml.getInt(p + "min_distance_px", o.min_distance_px);
  o.min_new_features = yaml.getInt(p + "min_new_features", o.min_new_features);
  o.quality_level = yaml.getDouble(p + "quality_level", o.quality_level);
  o.ransac_threshold_px = yaml.getDouble(p + "ransac_threshold_px", o.ransac_threshold_px);
  o.equalize = yaml.getBool(p + "equalize", o.equalize);
  o.clahe_clip_limit = yaml.getDouble(p + "clahe_clip_limit", o.clahe_clip_limit);
  o.clahe_tiles = yaml.getInt(p + "clahe_tiles", o.clahe_tiles);
  o.exposure_jump = yaml.getDouble(p + "exposure_jump", o.exposure_jump);
  o.klt_window = yaml.getInt(p + "klt_window", o.klt_window);
  o.klt_levels = yaml.getInt(p + "klt_levels", o.klt_levels);
  o.gyro_flow = yaml.getBool(p + "gyro_flow", o.gyro_flow);
  o.gyro_klt_levels = yaml.getInt(p + "gyro_klt_levels", o.gyro_klt_levels);
  o.forward_backward_check = yaml.getBool(p + "forward_backward_check", o.forward_backward_check);
  o.forward_backward_max_px =
      yaml.getDouble(p + "forward_backward_max_px", o.forward_backward_max_px);
  const std::string a = p + "anchors.";
  PatchAnchorOptions& an = o.anchors;
  an.enabled = yaml.getBool(a + "enabled", an.enabled);
  an.window = yaml.getInt(a + "window", an.window);
  an.max_shift_px = yaml.getDouble(a + "max_shift_px", an.max_shift_px);
  an.reanchor_frames = yaml.getInt(a + "reanchor_frames", an.reanchor_frames);
  an.max_iterations = yaml.getInt(a + "max_iterations", an.max_iterations);
  an.min_zncc = yaml.getDouble(a + "min_zncc", an.min_zncc);
  an.warp = yaml.getChoice(a + "warp", an.warp, {"translation", "similarity", "affine"});
  an.end_mismatched = yaml.getBool(a + "end_mismatched", an.end_mismatched);
  an.end_mismatched_before_init =
      yaml.getBool(a + "end_mismatched_before_init", an.end_mismatched_before_init);
  an.skip_backward_when_aligned =
      yaml.getBool(a + "skip_backward_when_aligned", an.skip_backward_when_aligned);
  if (an.window < 5 || an.window % 2 == 0)
    throw Error(yaml.where(a + "window") + " must be an odd number >= 5");
  if (an.max_shift_px <= 0) throw Error(yaml.where(a + "max_shift_px") + " must be positive");
  if (an.reanchor_frames < 0)
    throw Error(yaml.where(a + "reanchor_frames") + " must not be negative");
  if (an.max_iterations < 1) throw Error(yaml.where(a + "max_iterations") + " must be at least 1");
  if (an.min_zncc < -1 || an.min_zncc > 1)
    throw Error(yaml.where(a + "min_zncc") + " must be within [-1, 1]");
  if (o.exposure_jump < 0) throw Error(yaml.where(p + "exposure_jump") + " must not be negative");
  if (o.clahe_clip_limit <= 0)
    throw Error(yaml.where(p + "clahe_clip_limit") + " must be positive");
  if (o.clahe_tiles < 1) throw Error(yaml.where(p + "clahe_tiles") + " must be at least 1");
  if (o.max_features < 8) throw Error(yaml.where(p + "max_features") + " must be at least 8");
  if (o.min_distance_px < 1) throw Error(yaml.where(p + "min_distance_px") + " must be at least 1");
  if (o.min_new_features < 1 || o.min_new_features > o.max_features)
    throw Error(yaml.where(p + "min_new_features") + " must be in [1, max_features]");
  if (o.klt_window < 5 || o.klt_window % 2 == 0)
    throw Error(yaml.where(p + "klt_window") + " must be an odd number >= 5");
  if (o.klt_levels < 0) throw Error(yaml.where(p + "klt_levels") + " must not be negative");
  if (o.gyro_klt_levels < 0)
    throw Error(yaml.where(p + "gyro_klt_levels") + " must not be negative");
  return o;
}

}  // namespace alvio
