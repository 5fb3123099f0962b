#pragma once
// A planar laser scanner: beams cast into the city's walls and the moving objects around, with
// range noise and dropouts (glass, dark paint). Each scan's noise comes from its own index, so a
// scan is reproducible on its own.
#include <cstdint>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/Traffic.h"

namespace urbanslam::sim {

class LaserSimulator {
 public:
  LaserSimulator(const LaserOptions& options, const CityModel& city, const Traffic* traffic, uint64_t seed);

  // Scan number `index` taken at time t (seconds since start; timestamp is written as given)
  // from the vehicle pose (world frame).
  io::LaserScan scan(uint64_t index, double t, double timestamp, const common::Pose2& vehicle) const;
  size_t beams() const { return beams_; }

 private:
  LaserOptions options_;
  const CityModel& city_;
  const Traffic* traffic_;
  uint64_t seed_;
  size_t beams_;
  double angle_min_, increment_;
};

}  // namespace urbanslam::sim
