#include "urbanslam/slam/PathSubmaps.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/alignment/ShiftedRestarts.h"
#include "urbanslam/alignment/Voxels.h"
#include "urbanslam/slam/Map.h"

namespace urbanslam::slam {

namespace {

// The keyframes of pathSubmap: along the path each way from the centre, one every spacing_m.
std::vector<size_t> pathKeyframes(const Map& map, size_t center, size_t first, size_t last, const PathSubmapOptions& options) {
  const auto& kf = map.keyframes();
  std::vector<size_t> chosen;
  for (const int step : {-1, 1}) {
    double path = 0, last_taken = -options.spacing_m;
    for (size_t j = center;;) {
      if (kf[j].hasScan() && (j == center || path - last_taken >= options.spacing_m)) {
        if (j != center || step < 0) chosen.push_back(j);
        last_taken = path;
      }
      if ((step < 0 && j <= first) || (step > 0 && j >= last)) break;
      const size_t next = step < 0 ? j - 1 : j + 1;
      path += std::hypot(kf[next].pose.x - kf[j].pose.x, kf[next].pose.y - kf[j].pose.y);
      if (path > options.path_m) break;
      j = next;
    }
  }
  return chosen;
}

// The scans of `keyframes` in center's vehicle frame, thinned to a point per voxel.
alignment::PointSet submapOf(const Map& map, size_t center, const std::vector<size_t>& keyframes, double voxel_m) {
  const auto& kf = map.keyframes();
  alignment::PointSet all;
  const common::Pose2& origin = kf[center].pose;
  for (const size_t j : keyframes)
    alignment::appendTransformed(alignment::pointSetFromScan(map.scan(j), alignment::ScanModelOptions{}, true),
                                 common::between(origin, kf[j].pose), &all);
  alignment::PointSet out;
  for (const size_t i : alignment::firstPerVoxel(all, voxel_m)) out.push_back(all[i]);
  return out;
}

}  // namespace

alignment::PointSet pathSubmap(const Map& map, size_t center, size_t first, size_t last, const PathSubmapOptions& options) {
  return submapOf(map, center, pathKeyframes(map, center, first, last, options), options.voxel_m);
}

PathSubmapAlignment::PathSubmapAlignment(const Map& map, size_t earlier, size_t current, const common::Pose2& z, double reach_m,
                                         const PathSubmapOptions& options)
    : options_(options), reach_m_(reach_m) {
  if (earlier >= current || current >= map.size()) return;
  // Each visit on its own side of the halfway keyframe: a short loop's two neighbourhoods must
  // not share keyframes (they would align as the trajectory says, not as the closure does).
  const size_t half = earlier + (current - earlier) / 2;
  now_ = pathSubmap(map, current, half + 1, current, options);
  alignment::AlignerOptions ao;
  ao.method = alignment::Method::PlIcp;
  const std::vector<size_t> keyframes = pathKeyframes(map, earlier, 0, half, options);
  before_ = std::make_shared<const alignment::IndexedReference>(submapOf(map, earlier, keyframes, options.voxel_m));
  result_ = alignment::alignPointSets(*before_, now_, z, ao);
  // The tests see further: the earlier submap reaching reach_m further each way. (Its alignment
  // is not the measurement: along a street seen from its two ends, the longer submap let one
  // slide 1.4 m.) Where that reaches no further keyframe (a reach under spacing_m, the path's
  // end), it is the same submap and alignment.
  PathSubmapOptions wide = options;
  wide.path_m += std::max(0.0, reach_m);
  const std::vector<size_t> wide_keyframes = pathKeyframes(map, earlier, 0, half, wide);
  if (wide_keyframes == keyframes) {
    wide_ = before_;
    wide_result_ = result_;
  } else {
    wide_ = std::make_shared<const alignment::IndexedReference>(submapOf(map, earlier, wide_keyframes, options.voxel_m));
    wide_result_ = alignment::alignPointSets(*wide_, now_, z, ao);
  }
  if (wide_result_.converged || now_.empty() || wide_->points().empty()) return;
  // The share is of the current submap's points within near_m of the earlier submap's where the
  // alignment left them: where the earlier visit saw nothing (the current visit came from a street
  // it never drove, or the earlier one is the drive's start) there is nothing to disagree with.
  size_t near = 0;
  int index = 0;
  double d2 = 0;
  for (const auto& q : alignment::transformed(now_, wide_result_.transform))
    if (wide_->index().nearestWithin(q.p, options_.near_m * options_.near_m, &index, &d2)) ++near;
  disagree_ = static_cast<double>(wide_result_.matches) < ao.icp.min_overlap * static_cast<double>(near);
}

bool PathSubmapAlignment::ambiguous() const {
  if (!aligned() || !wide_result_.converged) return false;
  alignment::AlignerOptions ao;
  ao.method = alignment::Method::PlIcp;
  alignment::ShiftedRestarts restarts;
  restarts.first_shift_m = options_.min_shift_m;
  restarts.last_shift_m = reach_m_;
  restarts.same_minimum_m = 0.5 * options_.min_shift_m;
  restarts.min_match_ratio = 1.0 - options_.ambiguity_loss;
  return alignment::findsOtherMinimum(*wide_, now_, wide_result_, ao, restarts);
}

SubmapCheck alignPathSubmaps(const Map& map, size_t earlier, size_t current, const common::Pose2& z, double reach_m,
                             const PathSubmapOptions& options) {
  const PathSubmapAlignment p(map, earlier, current, z, reach_m, options);
  SubmapCheck out;
  out.aligned = p.aligned();
  out.measurement = p.measurement();
  out.ambiguous = p.ambiguous();
  out.disagree = p.disagree();
  return out;
}

}  // namespace urbanslam::slam
