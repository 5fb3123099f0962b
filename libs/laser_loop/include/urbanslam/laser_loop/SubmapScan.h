#pragma once
// A virtual 360° scan about the vehicle built from the returns of its recent scans. The features
// of §3.2.1 are rotation-invariant only for scans that cover the full circle; the thesis merged a
// front and a rear laser for that. With a single 180° laser the recent past supplies the rear
// view: every valid return of the scans taken over the last `window_m` of driving (including the
// current one) is moved into the current vehicle frame with the odometry poses, and each bearing
// sector of `beam_increment_deg` keeps its nearest return (a cheap stand-in for ray casting:
// older points behind a nearer surface are hidden). Sectors with no return are no-return beams.
//
// Only relative odometry over the window is used (a few metres to tens of metres, where wheel
// odometry or local scan matching drifts little), never a global or reference pose.
//
// Measured (share/laser_loop/README.md): on the Freiburg logs this does NOT help — held-out
// detection at 1 % FA falls (indoor → campus 34 % → 19 %, → held-out indoor 19 % → 7 % with a
// 5 m window), because the rear half comes from the path the robot arrived by, which differs
// between visits. Kept as an option (train-laser-loop --submap-window) so that is reproducible.
#include <deque>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/laser_loop/ScanFeatures.h"

namespace urbanslam::laser_loop {

class SubmapScanBuilder {
 public:
  // window_m > 0; beam_increment_deg > 0 (the sector width); returns beyond max_range_m dropped.
  SubmapScanBuilder(double window_m, double beam_increment_deg, double max_range_m);

  // Adds the scans (one instant, e.g. front + rear) taken at odometry pose `odom` and returns the
  // virtual scan about that pose (bearings relative to its heading).
  PolarScan add(const common::Pose2& odom, const std::vector<io::LaserScan>& scans);
  void clear() { window_.clear(); }
  size_t scansInWindow() const { return window_.size(); }

 private:
  struct Entry {
    common::Pose2 pose;
    double path_m = 0;
    std::vector<io::Point2> points;  // vehicle frame of that scan
  };
  double window_m_, increment_rad_, max_range_m_;
  size_t sectors_;
  double path_m_ = 0;
  std::deque<Entry> window_;
};

}  // namespace urbanslam::laser_loop
