#pragma once
// Options of the main job, one struct per ini section. Member names are the ini keys; units
// are in the names. declareOptions() is the single place that documents them, so check-ini,
// the config.ini written beside every run and ini/default.ini cannot drift apart.
#include <string>

#include "urbanslam/common/OptionsSchema.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/slam/MovingPoints.h"
#include "urbanslam/vision_loop/ImageLoopOptions.h"

namespace urbanslam::slam {

struct InputOptions {
  std::string laser_labels;  // comma-separated sensor labels to use; empty = every laser
  double min_range_m = 0.0;  // beams shorter than this are ignored (robot body, dust)
  double max_range_m = 0.0;  // beams at or beyond this are ignored; 0 = the sensor's own maximum
};

struct KeyframeOptions {
  double min_translation_m = 0.5;  // a new keyframe once the vehicle moved this far ...
  double min_rotation_deg = 10.0;  // ... or turned this much since the last keyframe
};

struct VehicleOptions {
  double wheelbase_m = 2.83;  // L: used when the log carries speed + steering (car-like vehicle)
};

// How the motion between two keyframes is predicted, and how uncertain it is.
struct MotionOptions {
  // auto: odometry readings, or the steering model for speed + steering logs.
  enum class Model { Auto, Odometry, Steering } model = Model::Auto;
  // Odometry noise per increment (sigma grows with distance and turning).
  double odometry_sigma_xy_per_m = 0.1;
  double odometry_sigma_xy_min_m = 0.002;
  double odometry_sigma_phi_per_rad = 0.3;
  double odometry_sigma_phi_per_m_rad = 0.1;
  double odometry_sigma_phi_min_rad = 0.0005;
  // Speed + steering noise (Q_v of the steering model, thesis eq. 2.19).
  double speed_sigma_mps = 0.2;
  double steering_sigma_deg = 3.0;
};

// Local SLAM: the odometry increment between keyframes refined by aligning their scans.
struct LocalOptions {
  bool scan_matching = true;
  int submap_keyframes = 5;  // the scan is matched against the last this many keyframes
  // The submap takes global SLAM's estimate of its keyframes this many keyframes late (0:
  // never; SubmapCorrections.h).
  int correction_lag_keyframes = 1;
  // The scans between keyframes are matched with the submap too, and the trajectory at odometry
  // times follows them (the filter and the map still hold keyframes only).
  bool match_every_scan = true;
  double match_min_interval_s = 0.0;  // ... but no scan sooner than this after the last matched one
  // The matcher (alignment/PriorScanMatcher.h): odometry prior and scan evidence weighed by
  // their uncertainties.
  double resolution_m = 0.05;    // likelihood grid cell
  double hit_sigma_m = 0.05;     // spread of a return about the surface it hit
  double miss_floor = 0.05;      // density of an unexplained return relative to a hit's peak
  double voxel_m = 0.2;          // the correlative search scores one scan point per voxel
  double grid_radius_m = 40.0;   // the likelihood grid covers the submap this far around its last keyframe
  double search_window_m = 0.3;  // the search reaches at least this far from the odometry
  double search_window_deg = 5.0;
  double odometry_outlier_probability = 1e-4;  // the odometry being wrong beyond its covariance
  double point_sigma_m = 0.01;                 // a return's distance to the reference surface (refinement)
  // The filter gets the match's covariance times this: consecutive matches share the submap's
  // points, so their errors are correlated, which the filter's independent edges cannot say.
  double covariance_scale = 4.0;
  double min_sigma_xy_m = 0.01;  // floors on the scan-matching uncertainty
  double min_sigma_phi_deg = 0.25;
};

// Global SLAM: loop-closure search, verification and the ESDF update.
struct LoopClosureOptions {
  bool enabled = true;
  // Candidates besides the nearest to the estimate where the pose is too uncertain to pick them
  // (appearance_min_sigma_m): none, or laser (the AdaBoost classifier's detections).
  enum class Detector { None, Laser } detector = Detector::Laser;
  std::string laser_model;              // classifier model file; empty = share/laser_loop/default.model
  std::string laser_model_360;          // the same for a laser that covers the full circle; empty = share/laser_loop/default-360.model
  double appearance_min_sigma_m = 3.0;  // detector = laser: the classifier adds candidates beyond this pose uncertainty
  double laser_threshold = 0.0;         // strong-classifier margin offset (higher: fewer false alarms)
  // Image proposals (Tree of Words, [image_loop]) go through the same alignment, gating and
  // confirmation as the laser candidates; without scans they are only recorded.
  enum class ImageDetector { None, TreeOfWords } image_detector = ImageDetector::TreeOfWords;
  double image_max_offset_s = 0.5;        // an image is attached to the nearest keyframe only this close in time
  int min_keyframe_gap = 30;              // closures only with keyframes at least this much older
  double search_radius_m = 4.0;           // initial set: earlier keyframes this close (+ 3 sigma)
  double mahalanobis_probability = 0.99;  // final set: chi2 (2 dof) gate on the relative position
  int max_candidates = 3;                 // aligned per keyframe, nearest (Mahalanobis) first
  // A laser that does not see all around shares no view with an earlier scan taken at the same
  // place heading the other way: such a candidate is replaced by the keyframe of that earlier
  // visit nearest to this far ahead of the current pose (0: off).
  double opposite_view_offset_m = 20.0;
  int every_n_keyframes = 1;  // search at every n-th keyframe
  // Along a revisit (a closure accepted at one of the last n-1 keyframes, none waiting for its
  // confirmation) the search waits for the n-th keyframe: consecutive keyframes' closures measure
  // the same walls from half a metre further on, and the filter counts each as independent.
  int revisit_every_n_keyframes = 3;
  // Where the pose relative to the nearest keyframe is uncertain beyond appearance_min_sigma_m,
  // the keyframes nearest the estimate are searched at every n-th keyframe only (detections still
  // at every one): from one keyframe to the next they are the same guesses about as wrong.
  int far_every_n_keyframes = 4;
  // Alignment of a candidate pair: auto (PL-ICP when the relative pose is well known, else
  // CRF-match + ICP) or one of the aligner's methods.
  enum class Method { Auto, Icp, PlIcp, Crf, CrfIcp } method = Method::Auto;
  double auto_local_max_m = 1.0;      // auto: PL-ICP when the relative pose is known to 3 sigma within this ...
  double auto_local_max_deg = 15.0;   // ... and this; CRF-match + ICP otherwise
  double max_rms_m = 0.08;            // alignment accepted only below this residual ...
  double min_matched_fraction = 0.5;  // ... and with this share of points matched
  // Pairs whose scans could not share min_matched_fraction of the current scan's points at any
  // relative pose the innovation gate admits are not aligned (alignment::mayMatchShare, a proof:
  // off gives the same map, slower; for measuring it and for tests of the later checks).
  bool view_test = true;
  // ... and with the geometry constraining every direction: the weakest / strongest translation
  // eigenvalue of the alignment's information at least this. A closure along a corridor slides.
  double min_constraint_ratio = 0.15;
  // ... and with no better minimum nearby: PL-ICP restarted from the result shifted by this
  // much along x and y must not find another pose matching clearly more points (a corridor's
  // repeated doors, a long facade). Checked only when the relative pose is uncertain enough
  // for the gate to admit such a shift. 0: off.
  double ambiguity_offset_m = 0.75;
  double ambiguity_min_gain = 0.05;  // "clearly more": this share more points matched
  // ... and with the two scans agreeing on free space: at most this share of either scan's
  // points may lie where the other scan's beams passed through (1: off).
  double max_free_space_conflict = 0.2;
  // ... and, for a closure beyond appearance_min_sigma_m, with no other alignment of the two
  // visits' path submaps (their keyframes within this much path, PathSubmaps.h) nearly as good as
  // the one from the closure, which becomes its measurement (0: off).
  double submap_check_path_m = 30;
  // The two scans are aligned and tested without the returns of things that moved (traffic,
  // people), judged by the keyframes up to this many places before and after each in the log
  // (MovingReturns.h; a keyframe's closures are sought once the keyframes after it are in the
  // map). 0: off.
  int moving_returns_neighbours = 5;
  double free_space_margin_m = 0.3;   // a point conflicts this far (+5 % of the range) inside free space
  double free_space_no_return_m = 0;  // a beam without a return saw free space this far (0: unknown)
  // A closure measured by the camera alone (no scans) is refused when the scene its two images
  // share would lie farther than this at the shortest distance between the cameras that the
  // estimate allows (3 sigma): two copies of a facade design far apart along a street look like
  // one facade seen from two nearby places, and only the distance tells them apart. The depth is
  // the lower quartile of the matched features' (the near facades of a street, 10-25 m in the
  // simulated cities); the bound leaves a factor of two for that depth's own error, where copies
  // 55-240 m apart would put their scenes 85 m and farther away (bench/camera/RESULTS.md).
  double max_scene_depth_m = 60;
  double covariance_scale = 4.0;
  double chi2_gate_probability = 0.99;  // innovation gate (3 dof); 0.99 measured better than 0.999 on Intel
  // A closure goes into the filter only once a second one, within this many keyframes, agrees
  // with it (0: no confirmation).
  int confirm_window = 3;
  double confirm_tolerance_m = 0.3;
  double confirm_tolerance_deg = 3.0;
  // With a camera too: a closure measured by the scans is confirmed at once when the images
  // nearest its two keyframes measure the same full relative pose (within the tolerances above).
  // The camera measures the full pose only where the estimate knows the pair within
  // appearance_min_sigma_m (GlobalSlam::allowsFullCameraPose), so farther closures still wait for
  // a second closure.
  bool camera_confirmation = true;
  // A closure that the gate refuses by less than two closures' quantile (6 dof) waits like an
  // unconfirmed one; with a later one that agrees with it and passes the joint gate of the two,
  // both go in (GlobalSlam::admit, Esdf::gateRelativePair).
  bool joint_gate = true;
};

struct EstimatorOptions {
  // esdf: the delayed-state information filter; dead_reckoning: the constraints composed, no filter.
  enum class Type { Esdf, DeadReckoning } type = Type::Esdf;
  bool relinearise = true;  // relinearise moved factors after a loop closure
  int recent_window = 30;   // poses recovered after each keyframe (constant time)
  // Global SLAM (filter updates, loop closures, recoveries) on a thread of its own, so that
  // local SLAM keeps up with the sensors while a closure is being worked in. Local SLAM never
  // reads global SLAM's estimates, so the results are the same either way.
  bool global_thread = true;
  // A full recovery after a loop closure only once the map has grown by this fraction since the
  // last one (0: after every closure): its cost spread over that many keyframes.
  double full_recovery_min_growth = 0.01;
  // ... and once the keyframes since the last one, at this many multiply-adds each, have paid for
  // its work (a factorisation of the whole map and its sparse inverse, Esdf::recoveryWork): a
  // map whose factor fills with every pass of a street (10^6 keyframes of a city) recovers less
  // often, and a full recovery's cost per keyframe stays bounded (0: the growth alone).
  double full_recovery_work_per_keyframe = 5e6;
  // Gauss-Newton steps of such a recovery, each a factorisation of the whole map. The factors a
  // step moves are relinearised at the start of the next recovery, not at the end of this one:
  // the factor the last step leaves is then the current information's, which the innovation
  // gate's exact covariances start from until the next recovery. The run's last recovery goes
  // on until nothing moves past 1 mm and 1e-4 rad.
  int full_recovery_steps = 1;
  // Beyond the first reduced_after_keyframes keyframes, one in four is a pose of the filter, the
  // others hang from it by local SLAM's constraints, their closures composed with the offsets
  // (KeyframeNodes.h): a quarter of the filter from there on, and of the whole-map factor's fill
  // from passes over mapped streets, for maps a little less stiff than with every keyframe a pose.
  // The first keyframes are poses each, so that a map of up to that many (any indoor log, a
  // city of tens of kilometres) is mapped as well as it can be and only a longer drive, whose
  // factor would otherwise outgrow the memory, trades some of that for memory.
  bool reduced_pose_graph = true;
  int reduced_after_keyframes = 100000;
};

struct MapOptions {
  double grid_resolution_m = 0.05;  // occupancy grid cell size
  double grid_max_cells = 1e8;      // grid.png's size bound: a larger map is written coarser there
  int grid_tile_cells = 2000;       // side of a grid tile (grid_tiles/), in cells
  int point_decimation = 1;         // keep every n-th map point in the point clouds
  // The keyframes' scans held in memory at most; the others wait in a spill file (deleted with
  // the run) until a loop candidate or an output reads them.
  double scan_cache_mb = 256;
  std::string scan_spill_dir;  // the spill file's folder; empty: the system's temporary folder
  // The point clouds leave out what another keyframe's scan saw through (MovingPoints.h).
  bool remove_moving_points = true;
  double moving_points_reach_m = 30;  // keyframes within this distance judge a keyframe's points
  int moving_points_views = 16;       // ... at most this many of them
  int moving_points_min_views = 2;    // a point seen through by this many has moved
  MovingPointsOptions movingPoints() const {
    MovingPointsOptions m;
    m.reach_m = moving_points_reach_m;
    m.views = moving_points_views;
    m.min_views = moving_points_min_views;
    return m;
  }
};

struct OutputOptions {
  bool write_ply_binary = true;
  bool write_ply_ascii = false;
  bool write_pcd = true;
  bool write_xyz = false;
  bool write_simplemap = true;
  bool write_grid = true;
  // A map too large for grid.png at grid_resolution_m (more than grid_max_cells: grid.png is
  // then coarser) is also written at full resolution as tiles: grid_tiles/.
  bool write_grid_tiles = true;
};

struct PipelineOptions {
  InputOptions input;
  KeyframeOptions keyframes;
  VehicleOptions vehicle;
  MotionOptions motion;
  LocalOptions local;
  LoopClosureOptions loop_closure;
  vision_loop::ImageLoopOptions image_loop;
  EstimatorOptions estimator;
  MapOptions map;
  OutputOptions output;
};

void declareOptions(common::OptionsSchema& schema, PipelineOptions& options);

// The options as JSON ({section: {key: value}}), for stats.json and check-ini --json.
common::Json optionsToJson(const PipelineOptions& options);
// The estimator's name as the ini spells it ("esdf", "dead_reckoning").
std::string estimatorName(EstimatorOptions::Type type);

// Defaults, overridden by the ini file when `ini_path` is not empty. Throws common::ConfigError.
// `resolved_ini` (optional) receives the resolved configuration as ini text.
PipelineOptions loadPipelineOptions(const std::string& ini_path, std::string* resolved_ini = nullptr);
// The same from ini text (`name` names it in errors), and the options as resolved ini text
// (numbers to 12 significant digits, as config.ini shows them).
PipelineOptions parsePipelineOptions(const std::string& ini_text, const std::string& name);
std::string optionsToIni(const PipelineOptions& options);

// The shipped data files under the project home (the repository, or $URBANSLAM_HOME), in one
// place for every program: the laser classifier's models and the Tree of Words vocabulary.
std::string defaultLaserModelPath(const std::string& home);
std::string defaultLaser360ModelPath(const std::string& home);
std::string defaultVocabularyPath(const std::string& home);
// Fills an empty [loop_closure] laser_model, laser_model_360 and [image_loop] vocabulary with those.
void resolveDefaultPaths(PipelineOptions& options, const std::string& home);
// The classifier for a laser whose scans look like `scan`: laser_model_360 when they cover the
// full circle, laser_model otherwise; an empty one is the shipped model's path relative to the
// working directory (laser_loop::kDefaultModelPath, kDefault360ModelPath).
std::string laserModelFor(const LoopClosureOptions& options, const io::LaserScan& scan);

}  // namespace urbanslam::slam
