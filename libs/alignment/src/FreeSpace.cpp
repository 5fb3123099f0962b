#include "urbanslam/alignment/FreeSpace.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::alignment {

FreeSpaceConflict freeSpaceConflict(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& b_in_a,
                                    const FreeSpaceOptions& options) {
  FreeSpaceConflict c;
  const size_t n = a.size();
  if (n < 3 || a.angle_increment_rad <= 0 || a.valid.size() != n) return c;
  // B's points in A's sensor frame: vehicle B -> vehicle A -> sensor A.
  const common::Pose2 to_sensor_a = common::compose(common::inverse(a.sensor_pose), b_in_a);
  for (const io::Point2& p : io::scanToPoints(b, true)) {
    const common::Pose2 q = common::compose(to_sensor_a, common::Pose2{p.x, p.y, 0});
    const double r = std::hypot(q.x, q.y);
    if (!(r >= options.min_range_m)) continue;
    // Bearing from beam 0, in [0, 2 pi): scans may start anywhere (-pi/2, -pi, 0 for 360° ones).
    double from_first = std::remainder(std::atan2(q.y, q.x) - a.angle_min_rad, 2 * M_PI);
    if (from_first < 0) from_first += 2 * M_PI;
    const double beam = std::round(from_first / a.angle_increment_rad);
    if (beam < 1 || beam > static_cast<double>(n) - 2) continue;  // outside A's field of view
    const size_t i = static_cast<size_t>(beam);
    // The free range along this bearing: the shortest of the beam and its neighbours, so a point
    // just beside an edge (where one neighbour goes far) is not counted against the near side.
    double free = HUGE_VAL;
    bool known = true;
    for (size_t k = i - 1; k <= i + 1 && known; ++k) {
      const double rk = a.ranges[k];
      if (!std::isfinite(rk) || rk < options.min_range_m) {
        known = false;  // no reading, or the robot itself
      } else if (a.valid[k]) {
        free = std::min(free, rk);
      } else if (options.no_return_free_m > 0 && (a.max_range_m <= 0 || rk >= a.max_range_m || rk >= options.no_return_free_m)) {
        free = std::min(free, options.no_return_free_m);  // a no-return, or a return beyond the range used
      } else {
        known = false;
      }
    }
    if (!known) continue;
    ++c.tested;
    if (r < free - options.margin_m - options.margin_fraction * free) ++c.conflicts;
  }
  return c;
}

double mutualFreeSpaceConflict(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& b_in_a,
                               const FreeSpaceOptions& options) {
  return std::max(freeSpaceConflict(a, b, b_in_a, options).fraction(),
                  freeSpaceConflict(b, a, common::inverse(b_in_a), options).fraction());
}

}  // namespace urbanslam::alignment
