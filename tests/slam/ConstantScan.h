#pragma once
// A front 180° scan, one beam per degree, every beam returning at the same range: a keyframe's
// scan where the test needs one but not its geometry.
#include <cmath>

#include "urbanslam/io/LaserScan.h"

namespace urbanslam::test {

inline io::LaserScan constantScan(double timestamp, float range_m, double max_range_m) {
  io::LaserScan s;
  s.timestamp = timestamp;
  s.angle_min_rad = -M_PI / 2;
  s.angle_increment_rad = M_PI / 180;
  s.max_range_m = max_range_m;
  s.ranges.assign(181, range_m);
  s.valid.assign(181, 1);
  return s;
}

}  // namespace urbanslam::test
