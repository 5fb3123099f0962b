#pragma once
// The alignment core works on its own point-set type rather than io::LaserScan so that it can
// be tested with synthetic geometry and fed from any sensor. A point remembers its beam index
// because consecutive beams are neighbours on the sweep: segmentation (subsampling), line
// normals (PL-ICP, line variance) and the CRF chain all rely on that ordering.
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::alignment {

struct ScanPoint {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();    // metres, in the scan's frame
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();  // Cartesian covariance (thesis eq. 3.4)
  double range_m = 0;                             // original range (eq. 3.1)
  double bearing_rad = 0;                         // original bearing
  int beam = 0;                                   // index of the beam in the original sweep
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // where it was seen from (the sensor), same frame as p
};

// Points in increasing beam order (the order of the sweep). A concatenation of several scans
// (a local submap) still works for ICP / PL-ICP and the covariance: line pieces and segments
// break where consecutive points jump; CRF-match's features assume a single sweep.
using PointSet = std::vector<ScanPoint>;

// The rigid transform as a rotation + translation; conversions to and from Pose2.
struct Rigid2 {
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();

  static Rigid2 fromPose(const common::Pose2& pose);
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const { return R * p + t; }
};

// The points (their covariances rotated, the sensor positions they were seen from moved with
// them) expressed in the frame in which `pose` is the
// frame of the set: p' = R(phi) p + t.
PointSet transformed(const PointSet& points, const common::Pose2& pose);
// The same appended to `out`, with no copy in between (a submap or a map tile concatenates the
// scans of many keyframes; callers reserve the whole first).
void appendTransformed(const PointSet& points, const common::Pose2& pose, PointSet* out);

}  // namespace urbanslam::alignment
