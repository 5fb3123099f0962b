#pragma once
// Ground-truth image loop pairs: two images far apart in time show the same place when most of
// the wall points one camera sees are seen by the other camera too. A point counts as seen when
// it lies inside the other camera's field of view, that camera's ray towards it ends on it (no
// nearer wall hides it) and it is at most kMaxScaleRatio times nearer or further (a facade seen
// from much further away is a different picture).
//
// The scans' truth (LoopTruth.h) compares end points with end points, which suits a laser whose
// beams sample the same directions each time; a camera's columns do not: two views of the same
// facade from a metre apart sample it at points over a metre apart once it is 30 m away, so a
// point-to-point test would miss most true revisits. Here each view keeps its column ranges and
// the test is against the ray, which does not depend on where the samples fall.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/sim/LoopTruth.h"
#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

class ImageLoopTruth {
 public:
  // `column_bearings`: each image column's ray in the camera frame (counter-clockwise, so they
  // decrease from the left edge to the right), as CameraRenderer::columnBearing gives them.
  ImageLoopTruth(const LoopTruthOptions& options, std::vector<double> column_bearings);

  // Adds a view (camera pose in the world, the range along every column, kNoHit where nothing)
  // and returns the pairs it forms with earlier views: older than min_gap_s, within
  // max_distance_m, headings within image_max_heading_deg, overlap ≥ min_overlap.
  std::vector<LoopPair> add(double t, const common::Pose2& camera, const std::vector<double>& column_ranges);

  // Fraction of `from`'s sampled wall points (every image_column_stride-th column) that `to` sees.
  double overlap(const common::Pose2& from, const std::vector<float>& from_ranges, const common::Pose2& to,
                 const std::vector<float>& to_ranges) const;

  static constexpr double kMaxScaleRatio = 2.0;  // apparent size change still counted as the same view

 private:
  struct View {
    double t;
    common::Pose2 pose;
    std::vector<float> ranges;  // per column; +inf: no wall within range
  };
  // The first column whose ray is not left of `bearing` (camera frame), or -1 outside the view.
  int columnOf(double bearing) const;

  LoopTruthOptions options_;
  std::vector<double> bearings_;
  std::vector<View> views_;
  std::unordered_map<int64_t, std::vector<uint32_t>> cells_;
};

}  // namespace urbanslam::sim
