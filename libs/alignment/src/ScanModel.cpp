#include "urbanslam/alignment/ScanModel.h"

#include <cmath>
#include <stdexcept>

namespace urbanslam::alignment {

Eigen::Matrix2d rangeBearingCovariance(double range_m, double max_range_m, const ScanModelOptions& options) {
  const double sr = options.range_sigma_m * (1.0 + range_m / max_range_m);
  Eigen::Matrix2d R;
  R << sr * sr, 0, 0, options.bearing_sigma_rad * options.bearing_sigma_rad;
  return R;
}

Eigen::Matrix2d cartesianCovariance(double range_m, double bearing_rad, double max_range_m, const ScanModelOptions& options) {
  const double c = std::cos(bearing_rad), s = std::sin(bearing_rad);
  Eigen::Matrix2d J;
  J << c, -range_m * s, s, range_m * c;
  return J * rangeBearingCovariance(range_m, max_range_m, options) * J.transpose();
}

namespace {

PointSet build(size_t n, const std::vector<double>& ranges, const std::vector<double>& bearings, double r_max,
               const ScanModelOptions& options, const std::vector<uint8_t>& valid) {
  PointSet out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (!valid.empty() && !valid[i]) continue;
    const double r = ranges[i], a = bearings[i];
    if (!std::isfinite(r) || !std::isfinite(a)) continue;
    if (r < options.min_range_m || r >= r_max) continue;  // r_max gate: no-return or too far
    ScanPoint q;
    q.range_m = r;
    q.bearing_rad = a;
    q.beam = static_cast<int>(i);
    q.p << r * std::cos(a), r * std::sin(a);
    q.cov = cartesianCovariance(r, a, r_max, options);
    out.push_back(q);
  }
  return out;
}

}  // namespace

PointSet makePointSet(const std::vector<double>& ranges_m, const std::vector<double>& bearings_rad, const ScanModelOptions& options,
                      const std::vector<uint8_t>& valid) {
  if (ranges_m.size() != bearings_rad.size() || (!valid.empty() && valid.size() != ranges_m.size()))
    throw std::invalid_argument("makePointSet: ranges, bearings and valid differ in length");
  return build(ranges_m.size(), ranges_m, bearings_rad, options.max_range_m, options, valid);
}

PointSet pointSetFromScan(const io::LaserScan& scan, const ScanModelOptions& options, bool in_vehicle_frame) {
  double r_max = options.max_range_m;
  if (scan.max_range_m > 0 && scan.max_range_m < r_max) r_max = scan.max_range_m;
  std::vector<double> ranges(scan.size()), bearings(scan.size());
  for (size_t i = 0; i < scan.size(); ++i) {
    ranges[i] = scan.ranges[i];
    bearings[i] = scan.bearing(i);
  }
  std::vector<uint8_t> valid = scan.valid;
  if (valid.size() != scan.size()) valid.clear();  // a scan without flags: ranges decide
  PointSet points = build(scan.size(), ranges, bearings, r_max, options, valid);
  if (in_vehicle_frame) points = transformed(points, scan.sensor_pose);
  return points;
}

}  // namespace urbanslam::alignment
