#pragma once
// Options of the main job, one struct per ini section. Member names are the ini keys; units
// are in the names. declareOptions() is the single place that documents them, so check-ini,
// the config.ini written beside every run and ini/default.ini cannot drift apart.
#include <string>

#include "urbanslam/common/OptionsSchema.h"

namespace urbanslam::slam {

struct InputOptions {
  std::string laser_labels;   // comma-separated sensor labels to use; empty = every laser
  double min_range_m = 0.0;   // beams shorter than this are ignored (robot body, dust)
  double max_range_m = 0.0;   // beams at or beyond this are ignored; 0 = the sensor's own maximum
};

struct KeyframeOptions {
  double min_translation_m = 0.5;  // a new keyframe once the vehicle moved this far ...
  double min_rotation_deg = 10.0;  // ... or turned this much since the last keyframe
};

struct VehicleOptions {
  double wheelbase_m = 2.83;  // L: used when the log carries speed + steering (car-like vehicle)
};

struct MapOptions {
  double grid_resolution_m = 0.05;  // occupancy grid cell size
  int point_decimation = 1;         // keep every n-th map point in the point clouds
};

struct OutputOptions {
  bool write_ply_binary = true;
  bool write_ply_ascii = false;
  bool write_pcd = true;
  bool write_xyz = false;
  bool write_simplemap = true;
  bool write_grid = true;
};

struct PipelineOptions {
  InputOptions input;
  KeyframeOptions keyframes;
  VehicleOptions vehicle;
  MapOptions map;
  OutputOptions output;
};

void declareOptions(common::OptionsSchema& schema, PipelineOptions& options);

// Defaults, overridden by the ini file when `ini_path` is not empty. Throws common::ConfigError.
// `resolved_ini` (optional) receives the resolved configuration as ini text.
PipelineOptions loadPipelineOptions(const std::string& ini_path, std::string* resolved_ini = nullptr);

}  // namespace urbanslam::slam
