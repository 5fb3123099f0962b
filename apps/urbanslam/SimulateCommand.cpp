// `urbanslam simulate`: drives a car through a procedurally generated city and writes what its
// sensors saw (a rawlog) with the ground truth a SLAM run is judged against.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulationOutputs.h"

namespace urbanslam::cli {

int simulateCommand(const Argv& args) {
  ArgParser ap("urbanslam simulate [--ini FILE] --out DIR [--no-rawlog] [--quiet] [--json]",
               "Simulates a drive through a city generated from a seed: 2D laser (walls, trees, parked and\n"
               "moving cars, pedestrians), a camera (textured facades; optional), wheel odometry and optionally\n"
               "GPS, with the ground truth.");
  ap.addOption("ini", "FILE",
               "simulation settings ([city], [vehicle], [route], [laser], [camera], [odometry], "
               "[gps], [traffic], [loops]); default: built-in defaults");
  ap.addOption("out", "DIR", "output folder (created if needed)");
  ap.addFlag("no-rawlog",
             "write only the ground truth (no city.rawlog, no images): to score a run that streamed\n"
             "the same ini with `urbanslam run --simulate` (the simulation is deterministic)");
  ap.addFlag("quiet", "no progress bar and no summary on stderr");
  ap.addFlag("json", "print a summary as one JSON object on stdout");
  ap.addEpilog(
      "outputs in DIR: city.rawlog (MRPT, observations layout: scans, odometry, GPS, and the true pose at\n"
      "every scan as CObservationRobotPose 'REFERENCE'), truth.tum (true vehicle poses at scan times),\n"
      "loops.csv (t_old,t_new,overlap,distance_m: scans more than [loops] min_gap_s apart whose views\n"
      "overlap), walls.csv (x1,y1,x2,y2) and walls.png (walls of the tiles the drive saw), config.ini.\n"
      "with [camera] enabled: city_Images/CAMERA_000000.png ... (referenced from the rawlog, MRPT's external\n"
      "images), image_loops.csv (the same columns as loops.csv, for images whose views also point within\n"
      "[loops] image_max_heading_deg) and image_loops.txt (those pairs by image name: eval-image-loop --gt).\n"
      "example: urbanslam simulate --ini ini/city-1km2.ini --out /tmp/city1");
  if (!ap.parse(args)) return 0;
  if (!ap.has("out")) throw common::InputError("simulate: --out DIR is required");
  const bool quiet = ap.flag("quiet");
  std::string resolved;
  const sim::SimOptions options = sim::loadSimOptions(ap.option("ini"), &resolved);

  common::ProgressBar bar("simulate", 1000, !quiet);
  const sim::SimulationSummary s = sim::writeSimulation(
      options, ap.option("out"), resolved, [&](double f) { bar.update(static_cast<uint64_t>(f * 1000)); }, !ap.flag("no-rawlog"));
  bar.finish();

  common::Json j = common::Json::object();
  j["out"] = ap.option("out");
  j["duration_s"] = s.duration_s;
  j["distance_m"] = s.distance_m;
  j["scans"] = s.scans;
  j["odometry"] = s.odometry;
  j["gps"] = s.gps;
  j["measurements"] = s.measurements;
  j["loop_pairs"] = s.loop_pairs;
  j["images"] = s.images;
  j["image_loop_pairs"] = s.image_loop_pairs;
  j["loop_images"] = s.loop_images;
  j["mean_render_ms"] = s.images > 0 ? 1000 * s.render_wall_s / s.images : 0.0;
  j["wall_segments"] = s.wall_segments;
  j["tiles_seen"] = s.tiles_seen;
  j["tiles_built"] = s.tiles_built;
  j["revisits_planned"] = s.revisits_planned;
  j["simulate_wall_s"] = s.simulate_wall_s;
  j["total_wall_s"] = s.total_wall_s;
  j["simulated_s_per_wall_s"] = s.simulate_wall_s > 0 ? s.duration_s / s.simulate_wall_s : 0.0;
  if (ap.flag("json")) std::cout << j.dump() << "\n";
  if (!quiet)
    std::cerr << "urbanslam simulate: " << s.distance_m / 1000 << " km in " << s.duration_s << " s simulated, " << s.scans << " scans, "
              << s.loop_pairs << " loop pairs, "
              << (s.images > 0 ? std::to_string(s.images) + " images (" +
                                     std::to_string(static_cast<int>(std::lround(1000 * s.render_wall_s / s.images))) + " ms each), " +
                                     std::to_string(s.image_loop_pairs) + " image loop pairs, "
                               : std::string())
              << s.wall_segments << " wall segments; " << s.duration_s / std::max(1e-9, s.simulate_wall_s) << "x real time ("
              << s.total_wall_s << " s with outputs)\n";
  return 0;
}

}  // namespace urbanslam::cli
