#include "urbanslam/sim/SimOptions.h"

#include <algorithm>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"

namespace urbanslam::sim {

void declareSimOptions(common::OptionsSchema& s, SimOptions& o) {
  auto& c = o.city;
  s.section("city", "The simulated city (a pure function of these keys and the seed)");
  s.add("seed", c.seed, 0, 2147483647, "", "everything random in the simulation follows from this");
  s.add("area_km2", c.area_km2, 0.01, 100.0, "km2", "square city of this area");
  s.add("block_min_m", c.block_min_m, 20.0, 500.0, "m", "smallest side of a block between streets");
  s.add("block_max_m", c.block_max_m, 20.0, 500.0, "m", "largest side of a block between streets");
  s.add("street_width_m", c.street_width_m, 12.0, 40.0, "m", "facade to facade (sidewalks, parking, two lanes)");
  s.add("tile_size_m", c.tile_size_m, 50.0, 1000.0, "m", "side of the lazily built tiles");
  s.add("cell_size_m", c.cell_size_m, 0.5, 50.0, "m", "ray-casting grid cell inside a tile");
  s.add("cache_tiles", c.cache_tiles, 9, 100000, "tiles", "tiles kept in memory (least recently used dropped)");
  s.add("park_probability", c.park_probability, 0.0, 1.0, "", "a block is a park (trees)");
  s.add("square_probability", c.square_probability, 0.0, 1.0, "", "a block is a paved square (fountain, benches, lamp posts)");
  s.add("dead_end_probability", c.dead_end_probability, 0.0, 1.0, "", "a street piece is closed half-way");
  s.add("repeated_design_probability", c.repeated_design_probability, 0.0, 1.0, "", "a facade copies one of design_count designs");
  s.add("design_count", c.design_count, 1, 100, "", "number of repeated facade designs");
  s.add("featureless_wall_probability", c.featureless_wall_probability, 0.0, 1.0, "", "a facade is a long plain wall");
  s.add("facade_min_m", c.facade_min_m, 2.0, 200.0, "m", "narrowest building along the street");
  s.add("facade_max_m", c.facade_max_m, 2.0, 500.0, "m", "widest building along the street");
  s.add("tree_spacing_m", c.tree_spacing_m, 0.0, 1000.0, "m", "mean gap between trees in a row; 0: none");
  s.add("tree_probability", c.tree_probability, 0.0, 1.0, "", "a sidewalk has a row of trees");
  s.add("lamp_post_spacing_m", c.lamp_post_spacing_m, 0.0, 1000.0, "m", "gap between lamp posts; 0: none");
  s.add("parked_car_probability", c.parked_car_probability, 0.0, 1.0, "", "a parking slot is taken");
  s.add("avenue_spacing_m", c.avenue_spacing_m, 0.0, 100000.0, "m",
        "parallel diagonal avenues across the grid this far apart (0: none; else at least 300)");
  s.add("avenue_width_m", c.avenue_width_m, 16.0, 60.0, "m", "an avenue's width, facade to facade");
  s.add("roundabout_probability", c.roundabout_probability, 0.0, 1.0, "", "a grid intersection is a roundabout (driven counter-clockwise)");
  s.add("roundabout_island_radius_m", c.roundabout_island_radius_m, 2.0, 20.0, "m", "radius of a roundabout's central island");
  s.add("buildings_per_block_min", c.buildings_per_block_min, 1, 50, "", "separate buildings on a block, at least ...");
  s.add("buildings_per_block_max", c.buildings_per_block_max, 1, 50, "", "... at most");
  s.add("alley_width_m", c.alley_width_m, 0.5, 20.0, "m", "gap between neighbouring buildings of a block");
  s.add("building_setback_max_m", c.building_setback_max_m, 0.0, 20.0, "m", "a building may stand back from the street up to this");

  auto& v = o.vehicle;
  s.section("vehicle", "The simulated car (bicycle model)");
  s.add("wheelbase_m", v.wheelbase_m, 0.5, 10.0, "m", "wheelbase L");
  s.add("max_steering_deg", v.max_steering_deg, 5.0, 60.0, "deg", "steering limit");
  s.add("max_steering_rate_deg_s", v.max_steering_rate_deg_s, 1.0, 1000.0, "deg/s", "steering rate limit");
  s.add("max_accel_mps2", v.max_accel_mps2, 0.1, 10.0, "m/s2", "acceleration limit");
  s.add("max_decel_mps2", v.max_decel_mps2, 0.1, 10.0, "m/s2", "braking limit");

  auto& r = o.route;
  s.section("route", "Where and how the car drives");
  s.add("seed", r.seed, 0, 1000000000, "", "the route's choices at intersections; 0: the city's seed (another drive through the same city: another seed)");
  s.add("route_length_km", r.route_length_km, 0.01, 10000.0, "km", "the drive ends after this distance");
  s.add("speed_mps", r.speed_mps, 1.0, 30.0, "m/s", "cruising speed");
  s.add("turn_speed_mps", r.turn_speed_mps, 0.5, 30.0, "m/s", "speed through turns");
  s.add("lookahead_min_m", r.lookahead_min_m, 0.5, 50.0, "m", "pure pursuit look-ahead distance, at least");
  s.add("lookahead_s", r.lookahead_s, 0.0, 10.0, "s", "pure pursuit look-ahead in seconds of travel");
  s.add("revisit_probability", r.revisit_probability, 0.0, 1.0, "", "after exploring, drive back to an earlier intersection");
  s.add("small_loop_probability", r.small_loop_probability, 0.0, 1.0, "",
        "a return goes to one of the last few intersections (a loop round a block or two) rather than any earlier one");
  s.add("explore_min_edges", r.explore_min_edges, 1, 1000, "", "street pieces explored before deciding, at least");
  s.add("explore_max_edges", r.explore_max_edges, 1, 1000, "", "... at most");
  s.add("straight_probability", r.straight_probability, 0.0, 1.0, "", "go straight at an intersection while exploring");
  s.add("start_time_s", r.start_time_s, 0.0, 1e10, "s", "timestamp of the start");
  s.add("step_s", r.step_s, 0.0001, 0.1, "s", "integration step of the vehicle model");

  auto& l = o.laser;
  s.section("laser", "2D laser scanner");
  s.add("enabled", l.enabled, "simulate the laser");
  s.add("label", l.label, {}, "sensor label in the rawlog");
  s.add("rate_hz", l.rate_hz, 0.1, 100.0, "Hz", "scans per second");
  s.add("fov_deg", l.fov_deg, 1.0, 360.0, "deg", "field of view (180: front, 360: all around)");
  s.add("angular_resolution_deg", l.angular_resolution_deg, 0.05, 10.0, "deg", "angle between beams");
  s.add("max_range_m", l.max_range_m, 1.0, 500.0, "m", "no return beyond this");
  s.add("range_sigma_m", l.range_sigma_m, 0.0, 1.0, "m", "range noise");
  s.add("range_sigma_per_m", l.range_sigma_per_m, 0.0, 0.1, "m/m", "range noise growing with range");
  s.add("dropout_probability", l.dropout_probability, 0.0, 1.0, "", "a beam gives no return");
  s.add("x_m", l.x_m, -10.0, 10.0, "m", "mounting: forward of the rear axle");
  s.add("y_m", l.y_m, -10.0, 10.0, "m", "mounting: to the left");
  s.add("yaw_deg", l.yaw_deg, -180.0, 180.0, "deg", "mounting: heading");

  auto& cam = o.camera;
  s.section("camera", "Camera rendered from the city (facade textures; images go to DIR/city_Images/)");
  s.add("enabled", cam.enabled, "simulate the camera");
  s.add("label", cam.label, {}, "sensor label in the rawlog");
  s.add("rate_hz", cam.rate_hz, 0.01, 100.0, "Hz", "images per second");
  s.add("width_px", cam.width_px, 16, 8192, "px", "image width");
  s.add("height_px", cam.height_px, 16, 8192, "px", "image height");
  s.add("hfov_deg", cam.hfov_deg, 10.0, 170.0, "deg", "horizontal field of view (square pixels)");
  s.add("cy_px", cam.cy_px, -1.0, 8192.0, "px", "image row of the horizon (lens shift); -1: the centre");
  s.add("x_m", cam.x_m, -10.0, 10.0, "m", "mounting: forward of the rear axle");
  s.add("y_m", cam.y_m, -10.0, 10.0, "m", "mounting: to the left");
  s.add("yaw_deg", cam.yaw_deg, -180.0, 180.0, "deg", "mounting: viewing direction (0 forward, 90 left, -90 right)");
  s.add("height_m", cam.height_m, 0.2, 10.0, "m", "mounting: height above the ground");
  s.add("max_range_m", cam.max_range_m, 1.0, 1000.0, "m", "walls beyond are not drawn");
  s.add("fog_distance_m", cam.fog_distance_m, 0.0, 100000.0, "m", "distance fog scale; 0: none");
  s.add("noise_sigma", cam.noise_sigma, 0.0, 50.0, "grey levels", "pixel noise, 1 sigma");
  s.add("noise_seed", cam.noise_seed, 0, 2147483647, "", "noise stream (combined with [city] seed)");

  auto& d = o.odometry;
  s.section("odometry", "Wheel odometry (wheel speed + steering encoder)");
  s.add("enabled", d.enabled, "simulate odometry");
  s.add("rate_hz", d.rate_hz, 0.1, 1000.0, "Hz", "readings per second");
  s.add("sigma_per_m", d.sigma_per_m, 0.0, 1.0, "m/m", "distance scale error (1 sigma, drifting over correlation_length_m)");
  s.add("sigma_per_rad", d.sigma_per_rad, 0.0, 1.0, "rad/rad", "heading error per radian turned (1 sigma, drifting)");
  s.add("sigma_phi_per_m_rad", d.sigma_phi_per_m_rad, 0.0, 1.0, "rad/m", "heading drift per metre travelled (1 sigma, drifting)");
  s.add("correlation_length_m", d.correlation_length_m, 0.01, 10000.0, "m", "distance over which the odometry errors decorrelate");
  s.add("scale_bias", d.scale_bias, -0.5, 0.5, "", "distance reads (1 + this) times the truth");
  s.add("steering_bias_deg", d.steering_bias_deg, -10.0, 10.0, "deg", "steering encoder offset");
  s.add("slip_probability", d.slip_probability, 0.0, 1.0, "1/s", "wheel slip events per second");
  s.add("slip_duration_s", d.slip_duration_s, 0.0, 10.0, "s", "length of a slip");
  s.add("slip_scale", d.slip_scale, 0.0, 5.0, "", "during a slip the distance reads up to this much too long");

  auto& g = o.gps;
  s.section("gps", "GPS fixes in local metres");
  s.add("enabled", g.enabled, "simulate GPS");
  s.add("rate_hz", g.rate_hz, 0.01, 100.0, "Hz", "fixes per second");
  s.add("sigma_m", g.sigma_m, 0.0, 100.0, "m", "position noise");
  s.add("outage_probability", g.outage_probability, 0.0, 1.0, "1/s", "outages per second");
  s.add("outage_min_s", g.outage_min_s, 0.0, 3600.0, "s", "shortest outage");
  s.add("outage_max_s", g.outage_max_s, 0.0, 3600.0, "s", "longest outage");
  s.add("multipath_probability", g.multipath_probability, 0.0, 1.0, "1/s", "multipath events per second (a reflection between facades)");
  s.add("multipath_jump_m", g.multipath_jump_m, 0.0, 1000.0, "m", "how far a multipath event shifts the fix");
  s.add("multipath_duration_s", g.multipath_duration_s, 0.0, 3600.0, "s", "how long a multipath event lasts");

  auto& t = o.traffic;
  s.section("traffic", "Moving objects the laser sees but the map must not keep");
  s.add("car_spacing_m", t.car_spacing_m, 0.0, 10000.0, "m", "mean gap between moving cars in a lane; 0: none");
  s.add("car_speed_mps", t.car_speed_mps, 0.0, 30.0, "m/s", "speed of moving cars");
  s.add("pedestrian_spacing_m", t.pedestrian_spacing_m, 0.0, 10000.0, "m", "mean gap between pedestrians on a sidewalk; 0: none");
  s.add("pedestrian_speed_mps", t.pedestrian_speed_mps, 0.0, 5.0, "m/s", "walking speed");
  s.add("clearance_m", t.clearance_m, 0.0, 100.0, "m", "moving objects this close to the car are left out (no collisions)");

  auto& p = o.loops;
  s.section("loops", "Ground-truth loop pairs (loops.csv; with a camera also image_loops.csv)");
  s.add("min_gap_s", p.min_gap_s, 0.0, 1e6, "s", "pairs at least this far apart in time");
  s.add("max_distance_m", p.max_distance_m, 0.1, 1000.0, "m", "sensor positions at most this far apart");
  s.add("match_radius_m", p.match_radius_m, 0.01, 10.0, "m", "an end point overlaps when the other scan has one this close");
  s.add("min_overlap", p.min_overlap, 0.0, 1.0, "", "reported from this overlap fraction");
  s.add("point_stride", p.point_stride, 1, 100, "beams", "compare every n-th beam end point");
  s.add("image_max_heading_deg", p.image_max_heading_deg, 0.0, 180.0, "deg",
        "image loop pairs (image_loops.csv): viewing directions at most this far apart");
  s.add("image_column_stride", p.image_column_stride, 1, 1000, "columns",
        "image loop pairs: wall points of every n-th image column are compared");
}

SimOptions loadSimOptions(const std::string& path, std::string* resolved_ini) {
  SimOptions o;
  common::OptionsSchema s;
  declareSimOptions(s, o);
  if (!path.empty()) s.load(common::IniFile::load(path));
  const std::string where = path.empty() ? std::string("defaults") : path;
  if (o.city.block_min_m > o.city.block_max_m) throw common::ConfigError(where + ": [city] block_min_m: larger than block_max_m");
  if (o.city.facade_min_m > o.city.facade_max_m) throw common::ConfigError(where + ": [city] facade_min_m: larger than facade_max_m");
  if (o.city.buildings_per_block_min > o.city.buildings_per_block_max)
    throw common::ConfigError(where + ": [city] buildings_per_block_min: larger than buildings_per_block_max");
  // Avenues closer than a block's length could split one street piece twice.
  if (o.city.avenue_spacing_m > 0 && o.city.avenue_spacing_m < std::max(300.0, 2 * (o.city.block_max_m + o.city.street_width_m)))
    throw common::ConfigError(where + ": [city] avenue_spacing_m: below 300 m or twice a block's pitch (0 turns avenues off)");
  if (o.route.explore_min_edges > o.route.explore_max_edges)
    throw common::ConfigError(where + ": [route] explore_min_edges: larger than explore_max_edges");
  if (o.gps.outage_min_s > o.gps.outage_max_s) throw common::ConfigError(where + ": [gps] outage_min_s: larger than outage_max_s");
  if (resolved_ini) *resolved_ini = s.toIni();
  return o;
}

}  // namespace urbanslam::sim
