#pragma once
// Options of the simulator, one struct per ini section. Member names are the ini keys; units are
// in the names. declareSimOptions() documents them (check-ini style) and loadSimOptions() rejects
// unknown keys and out-of-range values with the file, section and key.
#include <string>

#include "urbanslam/common/OptionsSchema.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/sim/CityOptions.h"

namespace urbanslam::sim {

struct VehicleOptions {
  double wheelbase_m = 2.7;
  double max_steering_deg = 35.0;
  double max_steering_rate_deg_s = 60.0;  // how fast the driver can turn the wheel
  double max_accel_mps2 = 1.5;
  double max_decel_mps2 = 2.5;
};

struct RouteOptions {
  int seed = 0;  // the route's choices at intersections; 0: the city's seed (another drive through the same city: another seed)
  double route_length_km = 3.0;
  double speed_mps = 10.0;              // cruising speed on straight streets
  double turn_speed_mps = 4.0;          // speed through a turn
  double lookahead_min_m = 4.0;         // pure pursuit look-ahead: at least this ...
  double lookahead_s = 0.6;             // ... or this many seconds of travel
  double revisit_probability = 0.9;     // after exploring, head back to an earlier intersection
  double small_loop_probability = 0.5;  // ... and then to one of the last few (a block-sized loop)
  int explore_min_edges = 2;            // street pieces driven freely before deciding to return
  int explore_max_edges = 12;
  double straight_probability = 0.5;   // at an intersection while exploring
  double start_time_s = 1700000000.0;  // timestamp of the first measurement
  double step_s = 0.01;                // integration step of the vehicle
};

struct LaserOptions {
  bool enabled = true;
  std::string label = "LASER";
  double rate_hz = 10.0;
  double fov_deg = 180.0;  // 180 (front) or 360
  double angular_resolution_deg = 0.5;
  double max_range_m = 80.0;
  double range_sigma_m = 0.01;
  double range_sigma_per_m = 0.0005;
  double dropout_probability = 0.01;           // a beam returns nothing (glass, black paint)
  double x_m = 1.5, y_m = 0.0, yaw_deg = 0.0;  // mounting pose on the vehicle (rear axle frame)
};

// A camera rendered from the city's walls (column ray casting, procedural facade textures).
// Looks horizontally; cy_px below the image centre shows more of the facades above the horizon,
// as a lens shift would (the image columns stay vertical).
struct CameraOptions {
  bool enabled = false;
  std::string label = "CAMERA";
  double rate_hz = 2.0;
  int width_px = 640, height_px = 480;
  double hfov_deg = 90.0;                      // horizontal field of view (square pixels: fy = fx)
  double cy_px = -1.0;                         // row of the horizon; < 0: the image centre
  double x_m = 1.0, y_m = 0.0, yaw_deg = 0.0;  // mounting pose on the vehicle (rear axle frame)
  double height_m = 1.6;                       // above the ground
  double max_range_m = 150.0;                  // nothing drawn beyond (sky and ground only)
  double fog_distance_m = 250.0;               // distance fog: contrast falls by 1/e over this; 0: none
  double noise_sigma = 2.0;                    // pixel noise (grey levels, 1 sigma)
  int noise_seed = 0;                          // with the city seed: the noise stream (same city, other noise)
};

struct OdometryOptions {
  bool enabled = true;
  double rate_hz = 50.0;
  // Errors that drift with the distance driven (Gauss-Markov, correlated over
  // correlation_length_m), as real wheel odometry's do (tyre load, floor, slip): white noise per
  // reading would average out at high rates and depend on rate_hz.
  double sigma_per_m = 0.04;           // distance scale error (1 sigma)
  double sigma_per_rad = 0.15;         // heading error per radian turned (1 sigma)
  double sigma_phi_per_m_rad = 0.032;  // heading drift per metre travelled (1 sigma)
  double correlation_length_m = 2.0;   // distance over which those errors decorrelate
  double scale_bias = 0.01;            // wheel radius error: distance reads (1 + this) too long
  double steering_bias_deg = 0.1;      // steering encoder offset: a straight drive curves
  double slip_probability = 0.01;      // per second: a wheel slip event
  double slip_duration_s = 0.5;
  double slip_scale = 0.3;  // during a slip the distance reads up to this much too long
};

struct GpsOptions {
  bool enabled = false;
  double rate_hz = 1.0;
  double sigma_m = 2.0;
  double outage_probability = 0.01;  // per second: the fix is lost (urban canyon)
  double outage_min_s = 5.0;
  double outage_max_s = 60.0;
  double multipath_probability = 0.01;  // per second: a reflected signal shifts the fix
  double multipath_jump_m = 15.0;       // size of the shift (direction random)
  double multipath_duration_s = 10.0;   // how long it lasts
};

struct TrafficOptions {
  double car_spacing_m = 120.0;  // mean gap between moving cars per lane; 0: none
  double car_speed_mps = 8.0;
  double pedestrian_spacing_m = 40.0;  // mean gap between pedestrians per sidewalk; 0: none
  double pedestrian_speed_mps = 1.3;
  double clearance_m = 8.0;  // moving objects this close to the vehicle are left out
};

struct LoopTruthOptions {
  double min_gap_s = 30.0;       // a loop pair is at least this far apart in time
  double max_distance_m = 15.0;  // ... and its sensor positions at most this far apart
  double match_radius_m = 0.3;   // a beam end point overlaps when the other scan has one this close
  double min_overlap = 0.5;      // reported when at least this fraction overlaps
  int point_stride = 4;          // every n-th beam end point is compared
  // Image loop pairs (image_loops.csv) use the keys above on the wall points of every
  // image_column_stride-th image column, and need the views to point within this angle.
  double image_max_heading_deg = 45.0;
  int image_column_stride = 8;
};

struct SimOptions {
  CityOptions city;
  VehicleOptions vehicle;
  RouteOptions route;
  LaserOptions laser;
  CameraOptions camera;
  OdometryOptions odometry;
  GpsOptions gps;
  TrafficOptions traffic;
  LoopTruthOptions loops;
};

void declareSimOptions(common::OptionsSchema& s, SimOptions& o);
// Defaults overlaid by the ini (path "" = defaults only). resolved_ini: the effective configuration.
SimOptions loadSimOptions(const std::string& path, std::string* resolved_ini = nullptr);

inline common::Pose2 laserMount(const LaserOptions& l) { return {l.x_m, l.y_m, l.yaw_deg * M_PI / 180.0}; }
inline common::Pose2 cameraMount(const CameraOptions& c) { return {c.x_m, c.y_m, c.yaw_deg * M_PI / 180.0}; }

}  // namespace urbanslam::sim
