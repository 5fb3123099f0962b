#pragma once
// The space one scan's beams passed through, as a point set remembers it (each point keeps its
// range and bearing): the shortest return per bearing bin. Used to ask which points of another
// scan or submap lie where this scan saw through (negative information, as FreeSpace.h gives it
// for loop closures on whole scans).
#include <vector>

#include <Eigen/Core>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/common/Pose2.h"

namespace urbanslam::alignment {

class BeamFreeSpace {
 public:
  // scan: points in the scan's frame with their sensor-frame range and bearing. A point conflicts
  // when it lies margin_m + margin_fraction * range in front of the returns of its bearing bin and
  // both neighbouring bins (bins without a return say nothing: glass, sky, out of range).
  BeamFreeSpace(const PointSet& scan, double margin_m, double margin_fraction);
  bool valid() const { return valid_; }
  // Of `points` (in the frame where the scan sits at `scan_pose`), how many the scan saw through.
  int conflicts(const std::vector<Eigen::Vector2d>& points, const common::Pose2& scan_pose) const;
  // Per point (sized like points): raised to kBehind where the scan's beams reach its bearing but
  // stopped short of it (hidden: the scan says nothing there), to kInView where they reached it,
  // to kSeenThrough where they passed it. Never lowered, so several scans can judge one point set.
  static constexpr char kUnseen = 0, kBehind = 1, kInView = 2, kSeenThrough = 3;
  void classify(const std::vector<Eigen::Vector2d>& points, const common::Pose2& scan_pose, std::vector<char>& state) const;

 private:
  size_t binOf(double bearing_rad) const;  // the bearing's bin, counted from 0 rad counter-clockwise

  bool valid_ = false;
  common::Pose2 sensor_;  // the sensor in the scan's frame (fitted from the points' own polar coordinates)
  double bin_rad_ = 0;
  std::vector<double> free_m_;  // per bin: the shortest return, or 0 (none)
  double margin_m_, margin_fraction_;
  double reach_m_ = 0;  // beyond this range every bin's returns hide a point (it can only be kBehind)
};

}  // namespace urbanslam::alignment
