#pragma once
// The four-step subsampling of thesis §3.3.2, needed because CRF-match is quadratic in the
// number of points:
//   1. remove the points whose range is at or beyond r_max;
//   2. split the rest into segments: consecutive points closer than a distance gate;
//   3. remove the segments with fewer points than a minimum size (isolated returns, clutter);
//   4. only if the remaining count is too far above the target, keep every k-th point,
//      k = floor(remaining / target) (thesis figure 3.6: 722 -> 604 -> 496 -> 124, target 100).
#include <vector>

#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

struct SubsamplingOptions {
  double max_range_m = 0;      // step 1; 0 = keep what the scan model's r_max gate let through
  double segment_gap_m = 0.5;  // step 2; consecutive points farther apart start a new segment
  int min_segment_points = 5;  // step 3
  // Step 3 is meant to drop clutter, not the scene: where it would keep less than this fraction
  // of the points (an outdoor scan of tree trunks, 2-4 returns each) the minimum size is lowered
  // step by step, down to 2, until it keeps that much.
  double min_kept_fraction = 0.75;
  int target_points = 100;        // step 4
  double decimation_slack = 0.5;  // step 4 runs when remaining > target * (1 + slack)
};

struct SubsamplingResult {
  PointSet segmented;         // after steps 1-3 (in sweep order)
  std::vector<int> segment;   // segment id of each point of `segmented`
  std::vector<int> source;    // index in the input of each point of `segmented`
  std::vector<int> selected;  // indices into `segmented` kept by step 4
  PointSet points;            // segmented[selected]
  // Counts after each step: {input, after r_max, after segmentation + small-segment removal,
  // after decimation}.
  int count_input = 0, count_after_range = 0, count_after_segments = 0, count_after_decimation = 0;
  int decimation_step = 1;
  int min_segment_points_used = 0;  // step 3's minimum after the min_kept_fraction rule
};

SubsamplingResult subsample(const PointSet& points, const SubsamplingOptions& options);

// Variant taking the raw count so that the thesis's "raw laser scan contains 722 points" (incl.
// the no-returns that a PointSet has already dropped) can be reported.
SubsamplingResult subsample(const PointSet& points, int raw_count, const SubsamplingOptions& options);

}  // namespace urbanslam::alignment
