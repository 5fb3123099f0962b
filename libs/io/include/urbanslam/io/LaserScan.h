#pragma once
// A planar laser scan as every module sees it: ranges with validity, the beam geometry, the
// sensor's mounting pose on the vehicle and the time it was taken. Deliberately free of MRPT
// headers (readers convert from mrpt::obs::CObservation2DRangeScan) so the algorithm modules
// stay cheap to compile.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::io {

struct LaserScan {
  double timestamp = 0;            // seconds (Unix time, or the log's own time base)
  std::string label;               // sensor label, e.g. "FLASER", "RLASER", "" (MRPT allows empty)
  std::vector<float> ranges;       // metres, beam i at angle_min_rad + i * angle_increment_rad
  std::vector<uint8_t> valid;      // 1 = a real return; 0 = no return / out of range / NaN
  double angle_min_rad = 0;        // bearing of beam 0 in the sensor frame (counter-clockwise)
  double angle_increment_rad = 0;  // > 0: beams ordered right to left
  double max_range_m = 0;          // readings >= this are no-returns
  common::Pose2 sensor_pose;       // sensor frame in the vehicle frame

  size_t size() const { return ranges.size(); }
  double bearing(size_t i) const { return angle_min_rad + static_cast<double>(i) * angle_increment_rad; }
  size_t validCount() const {
    size_t n = 0;
    for (auto v : valid) n += v ? 1 : 0;
    return n;
  }
};

// Cartesian points of the valid beams, in the sensor frame (or in the vehicle frame when
// in_vehicle_frame, i.e. with sensor_pose applied).
struct Point2 {
  double x = 0, y = 0;
};
std::vector<Point2> scanToPoints(const LaserScan& scan, bool in_vehicle_frame);

}  // namespace urbanslam::io
