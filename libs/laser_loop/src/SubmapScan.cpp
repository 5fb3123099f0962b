#include "urbanslam/laser_loop/SubmapScan.h"

#include <cmath>
#include <limits>

#include "urbanslam/common/Error.h"

namespace urbanslam::laser_loop {

SubmapScanBuilder::SubmapScanBuilder(double window_m, double beam_increment_deg, double max_range_m)
    : window_m_(window_m), increment_rad_(beam_increment_deg * M_PI / 180.0), max_range_m_(max_range_m) {
  if (!(window_m > 0) || !(beam_increment_deg > 0) || !(max_range_m > 0))
    throw common::InputError("submap scan: window, sector width and max range must be > 0");
  sectors_ = static_cast<size_t>(std::lround(2 * M_PI / increment_rad_));
  increment_rad_ = 2 * M_PI / static_cast<double>(sectors_);  // sectors tile the circle exactly
}

PolarScan SubmapScanBuilder::add(const common::Pose2& odom, const std::vector<io::LaserScan>& scans) {
  if (!window_.empty()) path_m_ += std::hypot(odom.x - window_.back().pose.x, odom.y - window_.back().pose.y);
  Entry e;
  e.pose = odom;
  e.path_m = path_m_;
  for (const auto& s : scans) {
    auto p = io::scanToPoints(s, true);
    e.points.insert(e.points.end(), p.begin(), p.end());
  }
  window_.push_back(std::move(e));
  while (window_.size() > 1 && path_m_ - window_.front().path_m > window_m_) window_.pop_front();

  std::vector<double> nearest(sectors_, std::numeric_limits<double>::infinity());
  const double r2max = max_range_m_ * max_range_m_;
  for (const auto& w : window_) {
    const common::Pose2 rel = common::between(odom, w.pose);  // that scan's frame in the current one
    const double c = std::cos(rel.phi), s = std::sin(rel.phi);
    for (const auto& p : w.points) {
      const double x = rel.x + c * p.x - s * p.y, y = rel.y + s * p.x + c * p.y;
      const double r2 = x * x + y * y;
      if (r2 >= r2max || r2 == 0) continue;
      // Sector centres at multiples of the increment: the current scan's beams (bearings
      // i·increment from its heading) then fall mid-sector, not on edges where rounding would
      // leave some sectors empty and put two beams in their neighbours.
      auto k = static_cast<size_t>(std::floor((std::atan2(y, x) + M_PI) / increment_rad_ + 0.5));
      if (k >= sectors_) k -= sectors_;  // +π wraps to −π
      nearest[k] = std::min(nearest[k], r2);
    }
  }
  PolarScan out;
  out.ranges.resize(sectors_);
  out.bearings.resize(sectors_);
  out.valid.resize(sectors_);
  for (size_t k = 0; k < sectors_; ++k) {
    out.bearings[k] = -M_PI + static_cast<double>(k) * increment_rad_;
    const bool hit = std::isfinite(nearest[k]);
    out.valid[k] = hit;
    out.ranges[k] = hit ? std::sqrt(nearest[k]) : 0.0;
  }
  out.angle_increment_rad = increment_rad_;
  out.closed = true;
  return out;
}

}  // namespace urbanslam::laser_loop
