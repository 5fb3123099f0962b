#include "urbanslam/slam/PipelineOptions.h"

#include "urbanslam/common/IniFile.h"

namespace urbanslam::slam {

void declareOptions(common::OptionsSchema& s, PipelineOptions& o) {
  s.section("input", "Which measurements of the log are used");
  s.add("laser_labels", o.input.laser_labels, {}, "comma-separated laser sensor labels to use (e.g. FLASER); empty: all lasers");
  s.add("min_range_m", o.input.min_range_m, 0.0, 100.0, "m", "ignore beams shorter than this");
  s.add("max_range_m", o.input.max_range_m, 0.0, 1000.0, "m", "ignore beams at or beyond this; 0 = the sensor's maximum");

  s.section("keyframes", "When a scan becomes a keyframe (a delayed pose of the map)");
  s.add("min_translation_m", o.keyframes.min_translation_m, 0.0, 100.0, "m", "new keyframe after this much travel");
  s.add("min_rotation_deg", o.keyframes.min_rotation_deg, 0.0, 180.0, "deg", "new keyframe after this much turning");

  s.section("vehicle", "Vehicle geometry");
  s.add("wheelbase_m", o.vehicle.wheelbase_m, 0.1, 20.0, "m", "wheelbase L for speed + steering logs");

  s.section("map", "Map products");
  s.add("grid_resolution_m", o.map.grid_resolution_m, 0.01, 2.0, "m", "occupancy grid cell size");
  s.add("point_decimation", o.map.point_decimation, 1, 1000, "", "keep every n-th point in the point clouds");

  s.section("output", "Which files a run writes besides the trajectory, stats.json and config.ini");
  s.add("write_ply_binary", o.output.write_ply_binary, "map.ply (binary little-endian PLY)");
  s.add("write_ply_ascii", o.output.write_ply_ascii, "map_ascii.ply (ASCII PLY)");
  s.add("write_pcd", o.output.write_pcd, "map.pcd (PCD v0.7)");
  s.add("write_xyz", o.output.write_xyz, "map.xyz (x y z per line)");
  s.add("write_simplemap", o.output.write_simplemap, "map.simplemap (MRPT CSimpleMap)");
  s.add("write_grid", o.output.write_grid, "grid.png + grid.yaml (occupancy grid, map_server convention)");
}

PipelineOptions loadPipelineOptions(const std::string& ini_path, std::string* resolved_ini) {
  PipelineOptions o;
  common::OptionsSchema schema;
  declareOptions(schema, o);
  if (!ini_path.empty()) schema.load(common::IniFile::load(ini_path));
  if (resolved_ini) *resolved_ini = schema.toIni();
  return o;
}

}  // namespace urbanslam::slam
