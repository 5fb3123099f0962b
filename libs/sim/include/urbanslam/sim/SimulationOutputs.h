#pragma once
// A whole simulated drive written to a folder: city.rawlog (MRPT, observations layout; camera
// images as PNG files in city_Images/, referenced from the rawlog), truth.tum (true vehicle
// poses at the scan and image times), loops.csv (ground-truth loop pairs of scans),
// image_loops.csv (the same for images) and image_loops.txt (the image pairs in the ground-truth
// format of eval-image-loop), walls.csv + walls.png (the walls of the tiles the drive saw) and
// config.ini (the resolved options). Every file but the images is written under a temporary name
// and renamed when complete.
#include <functional>
#include <string>

#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

struct SimulationSummary {
  double duration_s = 0;  // simulated time
  double distance_m = 0;
  size_t scans = 0, odometry = 0, gps = 0, measurements = 0;
  size_t images = 0, image_loop_pairs = 0, loop_images = 0;  // loop_images: images that close a loop
  double render_wall_s = 0;                                  // of simulate_wall_s: rendering images
  size_t loop_pairs = 0;
  size_t wall_segments = 0;
  size_t tiles_seen = 0, tiles_built = 0;
  size_t revisits_planned = 0;
  double simulate_wall_s = 0;  // wall time spent generating measurements (city, driving, sensors)
  double total_wall_s = 0;     // ... plus writing the outputs
};

// progress: called now and then with the fraction of the route driven. write_rawlog false: only
// the ground truth (truth.tum, loops, image loops, walls, config.ini), byte-identical to a full
// run's, to score a run that streamed the same simulation (`urbanslam run --simulate`).
SimulationSummary writeSimulation(const SimOptions& options, const std::string& dir, const std::string& resolved_ini,
                                  const std::function<void(double)>& progress = {}, bool write_rawlog = true);

}  // namespace urbanslam::sim
