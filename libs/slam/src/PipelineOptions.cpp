#include "urbanslam/slam/PipelineOptions.h"

#include "urbanslam/common/IniFile.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/laser_loop/ScanFeatures.h"
#include "urbanslam/vision_loop/ImageLoopOptions.h"

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

  s.section("motion", "Motion between keyframes: model and noise");
  s.add<MotionOptions::Model>(
      "model", o.motion.model,
      {{"auto", MotionOptions::Model::Auto}, {"odometry", MotionOptions::Model::Odometry}, {"steering", MotionOptions::Model::Steering}},
      "auto: steering model for speed+steering logs (Victoria Park), else odometry");
  s.add("odometry_sigma_xy_per_m", o.motion.odometry_sigma_xy_per_m, 0.0, 1.0, "m/m", "odometry position noise per metre travelled");
  s.add("odometry_sigma_xy_min_m", o.motion.odometry_sigma_xy_min_m, 1e-6, 1.0, "m", "odometry position noise floor per increment");
  s.add("odometry_sigma_phi_per_rad", o.motion.odometry_sigma_phi_per_rad, 0.0, 1.0, "rad/rad", "heading noise per radian turned");
  s.add("odometry_sigma_phi_per_m_rad", o.motion.odometry_sigma_phi_per_m_rad, 0.0, 1.0, "rad/m", "heading noise per metre travelled");
  s.add("odometry_sigma_phi_min_rad", o.motion.odometry_sigma_phi_min_rad, 1e-7, 1.0, "rad", "heading noise floor per increment");
  s.add("speed_sigma_mps", o.motion.speed_sigma_mps, 1e-4, 10.0, "m/s", "steering model: speed noise (Q_v)");
  s.add("steering_sigma_deg", o.motion.steering_sigma_deg, 1e-3, 45.0, "deg", "steering model: steering angle noise (Q_v)");

  s.section("local", "Local SLAM: the odometry between keyframes weighed against a scan match with the local submap");
  s.add("scan_matching", o.local.scan_matching,
        "match each scan with the local submap of the last keyframes, weighed against the odometry");
  s.add("submap_keyframes", o.local.submap_keyframes, 1, 100, "keyframes", "match against a local submap of the last this many keyframes");
  s.add("correction_lag_keyframes", o.local.correction_lag_keyframes, 0, 100, "keyframes",
        "the submap takes global SLAM's estimate of its keyframes (loop closures included) this many keyframes late; local SLAM waits "
        "only when global SLAM is further behind (0: never, the submap stays in local SLAM's own frame)");
  s.add("match_every_scan", o.local.match_every_scan,
        "also match the scans between keyframes with the submap; the trajectory at odometry times follows them (the map holds keyframes "
        "only)");
  s.add("resolution_m", o.local.resolution_m, 0.01, 1.0, "m", "likelihood grid cell of the correlative search");
  s.add("hit_sigma_m", o.local.hit_sigma_m, 0.005, 1.0, "m", "spread of a return about the surface it hit (likelihood grid)");
  s.add("miss_floor", o.local.miss_floor, 1e-6, 1.0, "", "density of a return the submap does not explain, relative to a hit's peak");
  s.add("match_min_interval_s", o.local.match_min_interval_s, 0.0, 10.0, "s",
        "a scan between keyframes is matched only this long after the last matched scan (a fast scanner's trajectory needs no node per "
        "scan)");
  s.add("grid_radius_m", o.local.grid_radius_m, 2.0, 200.0, "m",
        "the correlative search's likelihood grid covers the submap this far (along x and y) around its newest keyframe; returns beyond "
        "score nothing there (the refinement uses every return)");
  s.add("voxel_m", o.local.voxel_m, 0.01, 10.0, "m",
        "the correlative search scores one scan point per voxel of this size (the refinement uses every point)");
  s.add("search_window_m", o.local.search_window_m, 0.0, 10.0, "m",
        "the correlative search reaches at least this far from the odometry (and at least its 3 sigma and twice its travel: odometry can "
        "be wrong in direction)");
  s.add("search_window_deg", o.local.search_window_deg, 0.0, 180.0, "deg", "... and turns at least this far from it");
  s.add(
      "odometry_outlier_probability", o.local.odometry_outlier_probability, 0.0, 0.5, "",
      "probability that the odometry is wrong beyond its covariance (a missed turn, reversing, slip): what a scan match far from it pays");
  s.add("point_sigma_m", o.local.point_sigma_m, 0.001, 1.0, "m",
        "a return's distance to the submap's surface in the least-squares refinement");
  s.add("covariance_scale", o.local.covariance_scale, 0.1, 1000.0, "",
        "the filter gets the match's posterior covariance times this (consecutive matches share the submap's points: correlated errors)");
  s.add("min_sigma_xy_m", o.local.min_sigma_xy_m, 0.0, 1.0, "m", "floor on the scan-matching position sigma");
  s.add("min_sigma_phi_deg", o.local.min_sigma_phi_deg, 0.0, 10.0, "deg", "floor on the scan-matching heading sigma");

  s.section("loop_closure", "Global SLAM: loop-closure candidates, detection, alignment, gating");
  s.add("enabled", o.loop_closure.enabled, "search for loop closures");
  s.add<LoopClosureOptions::Detector>(
      "detector", o.loop_closure.detector, {{"none", LoopClosureOptions::Detector::None}, {"laser", LoopClosureOptions::Detector::Laser}},
      "where the pose is too uncertain to pick the candidates (appearance_min_sigma_m); none: the nearest to the estimate only; laser: the "
      "AdaBoost classifier's detections among every keyframe within reach as well");
  s.add("laser_model", o.loop_closure.laser_model, {}, "laser classifier model; empty: share/laser_loop/default.model");
  s.add("laser_model_360", o.loop_closure.laser_model_360, {},
        "laser classifier model for a laser whose scans cover the full circle; empty: share/laser_loop/default-360.model");
  s.add("appearance_min_sigma_m", o.loop_closure.appearance_min_sigma_m, 0.0, 1000.0, "m",
        "detector = laser: the classifier adds candidates once the pose relative to the nearest keyframe is this uncertain (1 sigma; from "
        "the estimate's guess, alignment reaches a few metres)");
  s.add("laser_threshold", o.loop_closure.laser_threshold, -100.0, 100.0, "",
        "classifier decision offset (higher: fewer false alarms): a keyframe scoring below is not a candidate");
  s.add<LoopClosureOptions::ImageDetector>(
      "image_detector", o.loop_closure.image_detector,
      {{"none", LoopClosureOptions::ImageDetector::None}, {"tree_of_words", LoopClosureOptions::ImageDetector::TreeOfWords}},
      "image loop closures: tree_of_words proposes pairs from keyframe images ([image_loop])");
  s.add("image_max_offset_s", o.loop_closure.image_max_offset_s, 0.0, 3600.0, "s",
        "an image belongs to the nearest keyframe in time only within this");
  s.add("min_keyframe_gap", o.loop_closure.min_keyframe_gap, 1, 100000, "keyframes",
        "only keyframes at least this much older are candidates");
  s.add("search_radius_m", o.loop_closure.search_radius_m, 0.1, 1000.0, "m", "initial candidate set: within this distance (plus 3 sigma)");
  s.add("mahalanobis_probability", o.loop_closure.mahalanobis_probability, 0.5, 0.999999, "",
        "final candidate set: chi2 (2 dof) probability");
  s.add("max_candidates", o.loop_closure.max_candidates, 1, 1000, "", "candidates aligned per keyframe");
  s.add("opposite_view_offset_m", o.loop_closure.opposite_view_offset_m, 0.0, 1000.0, "m",
        "a laser short of the full circle: a candidate heading the other way is replaced by the keyframe of its visit nearest to this "
        "far ahead of the current pose, where the two views meet (0: off)");
  s.add("every_n_keyframes", o.loop_closure.every_n_keyframes, 1, 1000, "keyframes", "search at every n-th keyframe");
  s.add("revisit_every_n_keyframes", o.loop_closure.revisit_every_n_keyframes, 1, 1000, "keyframes",
        "along a revisit (a closure accepted at one of the last n-1 keyframes, none awaiting confirmation) search at every n-th keyframe "
        "only: consecutive closures measure the same walls");
  s.add("far_every_n_keyframes", o.loop_closure.far_every_n_keyframes, 1, 1000, "keyframes",
        "beyond appearance_min_sigma_m, the keyframes nearest the estimate are candidates at every n-th keyframe only (as likely wrong at "
        "the next keyframe; detections are searched at every one)");
  s.add<LoopClosureOptions::Method>(
      "method", o.loop_closure.method,
      {{"auto", LoopClosureOptions::Method::Auto},
       {"icp", LoopClosureOptions::Method::Icp},
       {"plicp", LoopClosureOptions::Method::PlIcp},
       {"crf", LoopClosureOptions::Method::Crf},
       {"crf+icp", LoopClosureOptions::Method::CrfIcp}},
      "alignment of a candidate pair; auto: PL-ICP when the relative pose is well known, CRF-match + ICP otherwise");
  s.add("auto_local_max_m", o.loop_closure.auto_local_max_m, 0.0, 100.0, "m",
        "auto: PL-ICP when 3 sigma of the relative position is below this");
  s.add("auto_local_max_deg", o.loop_closure.auto_local_max_deg, 0.0, 180.0, "deg",
        "auto: ... and 3 sigma of the relative heading below this");
  s.add("max_rms_m", o.loop_closure.max_rms_m, 0.001, 10.0, "m", "alignment accepted only below this RMS residual");
  s.add("min_matched_fraction", o.loop_closure.min_matched_fraction, 0.0, 1.0, "",
        "alignment accepted only with this share of points matched");
  s.add("view_test", o.loop_closure.view_test,
        "a pair whose scans could share min_matched_fraction of the current scan's points nowhere the innovation gate admits is not "
        "aligned (a proof: off gives the same map, slower)");
  s.add("ambiguity_offset_m", o.loop_closure.ambiguity_offset_m, 0.0, 100.0, "m",
        "alignment accepted only when PL-ICP restarted from the result shifted by this along x and y finds no pose matching clearly more "
        "points; 0: off");
  s.add("ambiguity_min_gain", o.loop_closure.ambiguity_min_gain, 0.0, 1.0, "", "clearly more: this share more points matched");
  s.add("max_free_space_conflict", o.loop_closure.max_free_space_conflict, 0.0, 1.0, "",
        "alignment accepted only when at most this share of either scan's points lies in the other scan's free space; 1: off");
  s.add("submap_check_path_m", o.loop_closure.submap_check_path_m, 0.0, 1000.0, "m",
        "a closure beyond appearance_min_sigma_m is measured by aligning the two visits' keyframes within this much path as two submaps, "
        "and refused when another alignment of them is nearly as good; 0: off");
  s.add("moving_returns_neighbours", o.loop_closure.moving_returns_neighbours, 0, 100, "keyframes",
        "the two scans are aligned without the returns that the keyframes up to this many places before and after each saw through "
        "(traffic, people); 0: off");
  s.add("free_space_no_return_m", o.loop_closure.free_space_no_return_m, 0.0, 1000.0, "m",
        "free-space test: a beam without a return (or beyond max_range_m) saw free space this far; 0: says nothing");
  s.add("free_space_margin_m", o.loop_closure.free_space_margin_m, 0.0, 10.0, "m",
        "a point is in the other scan's free space when this much (+5 % of the range) in front of where its beam ended");
  s.add("max_scene_depth_m", o.loop_closure.max_scene_depth_m, 1.0, 1e6, "m",
        "a closure measured by the camera alone is refused when the scene its two images share would lie farther than this, the "
        "cameras as close as the estimate allows (3 sigma)");
  s.add("min_constraint_ratio", o.loop_closure.min_constraint_ratio, 0.0, 1.0, "",
        "alignment accepted only when its weakest translation direction has this share of the strongest's information (corridors slide)");
  s.add("covariance_scale", o.loop_closure.covariance_scale, 0.1, 1000.0, "", "inflation of the alignment covariance");
  s.add("chi2_gate_probability", o.loop_closure.chi2_gate_probability, 0.5, 0.9999999, "", "innovation gate (chi2, 3 dof)");
  s.add("confirm_window", o.loop_closure.confirm_window, 0, 1000, "keyframes",
        "a closure is added once another within this many keyframes agrees with it; 0: at once");
  s.add("confirm_tolerance_m", o.loop_closure.confirm_tolerance_m, 0.0, 100.0, "m", "agreement of two closures: position");
  s.add("confirm_tolerance_deg", o.loop_closure.confirm_tolerance_deg, 0.0, 180.0, "deg", "agreement of two closures: heading");
  s.add("camera_confirmation", o.loop_closure.camera_confirmation,
        "with a camera too: a closure the scans measured is confirmed at once when the images nearest its keyframes measure the same "
        "full relative pose (within the confirm tolerances)");
  s.add("joint_gate", o.loop_closure.joint_gate,
        "a closure the innovation gate refuses by less than two closures' quantile (6 dof) waits like an unconfirmed one: with one of "
        "the next confirm_window keyframes that agrees with it, the two go in when they pass the gate jointly");

  s.section("image_loop", "Tree of Words image loop-closure detection (used when [loop_closure] image_detector = tree_of_words)");
  vision_loop::declareImageLoopOptions(s, o.image_loop);

  s.section("estimator", "The estimator behind the map");
  s.add<EstimatorOptions::Type>("type", o.estimator.type,
                                {{"esdf", EstimatorOptions::Type::Esdf}, {"dead_reckoning", EstimatorOptions::Type::DeadReckoning}},
                                "esdf: the delayed-state information filter; dead_reckoning: odometry only");
  s.add("relinearise", o.estimator.relinearise, "relinearise moved factors after a loop closure (reaches the batch optimum)");
  s.add("recent_window", o.estimator.recent_window, 1, 100000, "poses", "poses recovered after each keyframe");
  s.add("global_thread", o.estimator.global_thread, "global SLAM on a thread of its own: local SLAM never waits (same results)");
  s.add("full_recovery_min_growth", o.estimator.full_recovery_min_growth, 0.0, 10.0, "",
        "full recovery after a closure once the map grew by this fraction since the last (0: every closure)");
  s.add("full_recovery_work_per_keyframe", o.estimator.full_recovery_work_per_keyframe, 0.0, 1e12, "multiply-adds",
        "... and once the keyframes since the last, at this much each, have paid for its work (a factorisation of the whole map and its "
        "sparse inverse): a full recovery's cost per keyframe bounded (0: the growth alone)");
  s.add("full_recovery_steps", o.estimator.full_recovery_steps, 1, 100, "",
        "Gauss-Newton steps of a full recovery after a closure, each a factorisation of the whole map; what they move is relinearised "
        "when the next recovery starts (the run's last goes on until nothing moves past 1 mm and 1e-4 rad)");
  s.add("reduced_pose_graph", o.estimator.reduced_pose_graph,
        "beyond reduced_after_keyframes, one keyframe in four is a filter pose, the three after it hang from it (their closures go in "
        "composed with their offsets)");
  s.add("reduced_after_keyframes", o.estimator.reduced_after_keyframes, 0, 1000000000, "keyframes",
        "reduced_pose_graph: the first this many keyframes are filter poses each (0: one in four from the start)");

  s.section("map", "Map products");
  s.add("grid_resolution_m", o.map.grid_resolution_m, 0.01, 2.0, "m", "occupancy grid cell size");
  s.add("grid_max_cells", o.map.grid_max_cells, 1e4, 1e9, "cells", "grid.png's size bound: a larger map is written coarser there");
  s.add("grid_tile_cells", o.map.grid_tile_cells, 100, 10000, "cells", "side of a tile of grid_tiles/");
  s.add("point_decimation", o.map.point_decimation, 1, 1000, "", "keep every n-th point in the point clouds");
  s.add("scan_cache_mb", o.map.scan_cache_mb, 0, 1e6, "MB", "keyframe scans held in memory at most; the rest wait in a spill file");
  s.add("scan_spill_dir", o.map.scan_spill_dir, {},
        "folder of the spill files (scans, older closure records and odometry readings; deleted with the run); empty: the system's "
        "temporary folder");
  s.add("remove_moving_points", o.map.remove_moving_points,
        "leave out of the point clouds the points another keyframe's scan saw through (cars, people, doors that moved)");
  s.add("moving_points_reach_m", o.map.moving_points_reach_m, 1.0, 1000.0, "m", "keyframes within this distance judge a keyframe's points");
  s.add("moving_points_views", o.map.moving_points_views, 1, 1000, "keyframes", "at most this many of them, spread over the log");
  s.add("moving_points_min_views", o.map.moving_points_min_views, 1, 1000, "keyframes", "a point seen through by this many has moved");

  s.section("output", "Which files a run writes besides the trajectory, stats.json and config.ini");
  s.add("write_ply_binary", o.output.write_ply_binary, "map.ply (binary little-endian PLY)");
  s.add("write_ply_ascii", o.output.write_ply_ascii, "map_ascii.ply (ASCII PLY)");
  s.add("write_pcd", o.output.write_pcd, "map.pcd (PCD v0.7)");
  s.add("write_xyz", o.output.write_xyz, "map.xyz (x y z per line)");
  s.add("write_simplemap", o.output.write_simplemap, "map.simplemap (MRPT CSimpleMap)");
  s.add("write_grid", o.output.write_grid, "grid.png + grid.yaml (occupancy grid, map_server convention)");
  s.add("write_grid_tiles", o.output.write_grid_tiles,
        "grid_tiles/ (the grid at full resolution in tiles, when grid.png had to be coarser than grid_resolution_m)");
}

common::Json optionsToJson(const PipelineOptions& options) {
  PipelineOptions copy = options;  // the schema binds to mutable members
  common::OptionsSchema schema;
  declareOptions(schema, copy);
  return schema.toJson();
}

PipelineOptions loadPipelineOptions(const std::string& ini_path, std::string* resolved_ini) {
  PipelineOptions o;
  common::OptionsSchema schema;
  declareOptions(schema, o);
  if (!ini_path.empty()) schema.load(common::IniFile::load(ini_path));
  if (resolved_ini) *resolved_ini = schema.toIni();
  return o;
}

PipelineOptions parsePipelineOptions(const std::string& ini_text, const std::string& name) {
  PipelineOptions o;
  common::OptionsSchema schema;
  declareOptions(schema, o);
  schema.load(common::IniFile::parse(ini_text, name));
  return o;
}

std::string optionsToIni(const PipelineOptions& options) {
  PipelineOptions copy = options;  // the schema binds to mutable members
  common::OptionsSchema schema;
  declareOptions(schema, copy);
  return schema.toIni();
}

std::string defaultLaserModelPath(const std::string& home) { return home + "/" + laser_loop::kDefaultModelPath; }

std::string defaultLaser360ModelPath(const std::string& home) { return home + "/" + laser_loop::kDefault360ModelPath; }

std::string laserModelFor(const LoopClosureOptions& options, const io::LaserScan& scan) {
  // A scan of the whole circle has the whole place in its range distribution; the model trained
  // on such scans tells places apart that the general one confuses (share/laser_loop/README.md).
  if (laser_loop::coversFullCircle(scan))
    return options.laser_model_360.empty() ? laser_loop::kDefault360ModelPath : options.laser_model_360;
  return options.laser_model.empty() ? laser_loop::kDefaultModelPath : options.laser_model;
}

std::string defaultVocabularyPath(const std::string& home) { return home + "/" + vision_loop::kDefaultVocabularyPath; }

void resolveDefaultPaths(PipelineOptions& options, const std::string& home) {
  if (options.loop_closure.laser_model.empty()) options.loop_closure.laser_model = defaultLaserModelPath(home);
  if (options.loop_closure.laser_model_360.empty()) options.loop_closure.laser_model_360 = defaultLaser360ModelPath(home);
  if (options.image_loop.vocabulary.empty()) options.image_loop.vocabulary = defaultVocabularyPath(home);
}

std::string estimatorName(EstimatorOptions::Type type) { return type == EstimatorOptions::Type::Esdf ? "esdf" : "dead_reckoning"; }

}  // namespace urbanslam::slam
