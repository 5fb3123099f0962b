#include <cmath>

#include "urbanslam/io/Measurements.h"

namespace urbanslam::io {

std::vector<Point2> scanToPoints(const LaserScan& scan, bool in_vehicle_frame) {
  std::vector<Point2> pts;
  pts.reserve(scan.ranges.size());
  const double c = std::cos(scan.sensor_pose.phi), s = std::sin(scan.sensor_pose.phi);
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.valid[i]) continue;
    const double a = scan.bearing(i), r = scan.ranges[i];
    const double x = r * std::cos(a), y = r * std::sin(a);
    if (in_vehicle_frame)
      pts.push_back({scan.sensor_pose.x + c * x - s * y, scan.sensor_pose.y + s * x + c * y});
    else
      pts.push_back({x, y});
  }
  return pts;
}

double timestampOf(const Measurement& m) {
  return std::visit([](const auto& v) { return v.timestamp; }, m);
}

}  // namespace urbanslam::io
