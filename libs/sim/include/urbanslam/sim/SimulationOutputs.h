#pragma once
// A whole simulated drive written to a folder: city.rawlog (MRPT, observations layout),
// truth.tum (true vehicle poses at the scan times), loops.csv (ground-truth loop pairs),
// walls.csv + walls.png (the walls of the tiles the drive saw) and config.ini (the resolved
// options). Every file is written under a temporary name and renamed when complete.
#include <functional>
#include <string>

#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

struct SimulationSummary {
  double duration_s = 0;      // simulated time
  double distance_m = 0;
  size_t scans = 0, odometry = 0, gps = 0, measurements = 0;
  size_t loop_pairs = 0;
  size_t wall_segments = 0;
  size_t tiles_seen = 0, tiles_built = 0;
  size_t revisits_planned = 0;
  double simulate_wall_s = 0;  // wall time spent generating measurements (city, driving, sensors)
  double total_wall_s = 0;     // ... plus writing the outputs
};

// progress: called now and then with the fraction of the route driven.
SimulationSummary writeSimulation(const SimOptions& options, const std::string& dir, const std::string& resolved_ini,
                                  const std::function<void(double)>& progress = {});

}  // namespace urbanslam::sim
