#include "urbanslam/alignment/Subsampling.h"

#include <algorithm>

namespace urbanslam::alignment {

SubsamplingResult subsample(const PointSet& points, const SubsamplingOptions& options) {
  return subsample(points, static_cast<int>(points.size()), options);
}

SubsamplingResult subsample(const PointSet& points, int raw_count, const SubsamplingOptions& options) {
  SubsamplingResult out;
  out.count_input = raw_count;
  // 1. r_max gate.
  PointSet in_range;
  std::vector<int> in_range_source;
  in_range.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (options.max_range_m > 0 && points[i].range_m >= options.max_range_m) continue;
    in_range.push_back(points[i]);
    in_range_source.push_back(static_cast<int>(i));
  }
  out.count_after_range = static_cast<int>(in_range.size());

  // 2. segmentation by the distance gate between consecutive points of the sweep.
  const double gap2 = options.segment_gap_m * options.segment_gap_m;
  std::vector<std::pair<size_t, size_t>> segments;  // [begin, end)
  for (size_t i = 0; i < in_range.size();) {
    size_t j = i + 1;
    while (j < in_range.size() && (in_range[j].p - in_range[j - 1].p).squaredNorm() < gap2) ++j;
    segments.emplace_back(i, j);
    i = j;
  }
  // 3. small-segment removal.
  int min_size = std::max(1, options.min_segment_points);
  auto keptWith = [&](int m) {
    size_t kept = 0;
    for (const auto& [b, e] : segments)
      if (static_cast<int>(e - b) >= m) kept += e - b;
    return kept;
  };
  while (min_size > 2 && static_cast<double>(keptWith(min_size)) < options.min_kept_fraction * static_cast<double>(in_range.size()))
    --min_size;
  out.min_segment_points_used = min_size;
  int id = 0;
  for (const auto& [b, e] : segments) {
    if (static_cast<int>(e - b) < min_size) continue;
    for (size_t k = b; k < e; ++k) {
      out.segmented.push_back(in_range[k]);
      out.segment.push_back(id);
      out.source.push_back(in_range_source[k]);
    }
    ++id;
  }
  out.count_after_segments = static_cast<int>(out.segmented.size());

  // 4. decimation, only when the surplus over the target is large.
  const int n = out.count_after_segments;
  const int target = std::max(1, options.target_points);
  out.decimation_step = 1;
  if (n > target * (1.0 + options.decimation_slack)) out.decimation_step = std::max(1, n / target);
  for (int i = 0; i < n; i += out.decimation_step) out.selected.push_back(i);
  out.points.reserve(out.selected.size());
  for (int i : out.selected) out.points.push_back(out.segmented[i]);
  out.count_after_decimation = static_cast<int>(out.points.size());
  return out;
}

}  // namespace urbanslam::alignment
