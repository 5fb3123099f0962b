#pragma once
// The space one scan's beams passed through, as a point set remembers it (each point keeps its
// range and bearing): the shortest return per bearing bin. Used to ask which points of another
// scan or submap lie where this scan saw through (negative information, as FreeSpace.h gives it
// for loop closures on whole scans).
#include <cmath>
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
  // The bearing's bin, counted from 0 rad counter-clockwise (here, to be inlined into classify's
  // loop).
  size_t binOf(double bearing_rad) const {
    // atan2's range needs no reduction (std::remainder costs as much as the atan2 before it).
    double from_zero = std::abs(bearing_rad) <= M_PI ? bearing_rad : std::remainder(bearing_rad, 2 * M_PI);
    if (from_zero < 0) from_zero += 2 * M_PI;
    // At most 2 pi over the bin width: at most the bin count, which is bin 0 again (a compare
    // instead of an integer division, which was a tenth of classify's time).
    const size_t b = static_cast<size_t>(from_zero / bin_rad_);
    return b >= free_m_.size() ? b - free_m_.size() : b;
  }

  bool valid_ = false;
  common::Pose2 sensor_;  // the sensor in the scan's frame (fitted from the points' own polar coordinates)
  double bin_rad_ = 0;
  std::vector<double> free_m_;  // per bin: the shortest return, or 0 (none)
  double margin_m_, margin_fraction_;
  double reach_m_ = 0;  // beyond this range every bin's returns hide a point (it can only be kBehind)
};

}  // namespace urbanslam::alignment
