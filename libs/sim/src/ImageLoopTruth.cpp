#include "urbanslam/sim/ImageLoopTruth.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "urbanslam/common/Error.h"

namespace urbanslam::sim {

ImageLoopTruth::ImageLoopTruth(const LoopTruthOptions& options, std::vector<double> column_bearings)
    : options_(options), bearings_(std::move(column_bearings)) {
  if (bearings_.size() < 2) throw common::InputError("image loop truth: a camera needs at least two columns");
  for (size_t i = 1; i < bearings_.size(); ++i)
    if (!(bearings_[i] < bearings_[i - 1])) throw common::InputError("image loop truth: column bearings must decrease");
}

int ImageLoopTruth::columnOf(double bearing) const {
  if (bearing > bearings_.front() || bearing < bearings_.back()) return -1;
  // First column whose bearing is not above `bearing` (the array decreases).
  const auto it = std::lower_bound(bearings_.begin(), bearings_.end(), bearing, std::greater<double>());
  return static_cast<int>(it - bearings_.begin());
}

double ImageLoopTruth::overlap(const common::Pose2& from, const std::vector<float>& from_ranges, const common::Pose2& to,
                               const std::vector<float>& to_ranges) const {
  size_t points = 0, seen = 0;
  const size_t stride = static_cast<size_t>(std::max(1, options_.image_column_stride));
  for (size_t x = 0; x < from_ranges.size(); x += stride) {
    const double r = from_ranges[x];
    if (!std::isfinite(r)) continue;
    ++points;
    const double a = from.phi + bearings_[x];
    const double px = from.x + r * std::cos(a) - to.x, py = from.y + r * std::sin(a) - to.y;
    const double d = std::hypot(px, py);
    if (d > kMaxScaleRatio * r || r > kMaxScaleRatio * d) continue;
    const int c = columnOf(common::wrapToPi(std::atan2(py, px) - to.phi));
    if (c < 0) continue;
    // The true ray towards the point lies between columns c-1 and c: it ends on the point when
    // the point's distance is within the ranges those two columns met (a wall between them is
    // continuous), give or take the match radius and 2 % for the sampled geometry.
    const float r0 = to_ranges[static_cast<size_t>(c > 0 ? c - 1 : c)], r1 = to_ranges[static_cast<size_t>(c)];
    const double tol = options_.match_radius_m + 0.02 * d;
    const double lo = std::min(r0, r1), hi = std::max(r0, r1);
    if (!std::isfinite(lo)) continue;  // an open direction there: the point is beyond its range
    if (d >= lo - tol && (d <= hi + tol || !std::isfinite(hi))) ++seen;
  }
  return points ? static_cast<double>(seen) / static_cast<double>(points) : 0.0;
}

std::vector<LoopPair> ImageLoopTruth::add(double t, const common::Pose2& camera, const std::vector<double>& column_ranges) {
  if (column_ranges.size() != bearings_.size()) throw common::InputError("image loop truth: one range per column expected");
  View v{t, camera, {}};
  v.ranges.reserve(column_ranges.size());
  for (double r : column_ranges) v.ranges.push_back(std::isfinite(r) ? static_cast<float>(r) : std::numeric_limits<float>::infinity());

  std::vector<LoopPair> out;
  const double d = options_.max_distance_m;
  const double max_heading = options_.image_max_heading_deg * M_PI / 180.0;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) {
      const auto it = cells_.find(positionCellKey(camera.x + dx * d, camera.y + dy * d, d));
      if (it == cells_.end()) continue;
      for (uint32_t k : it->second) {
        const View& o = views_[k];
        const double dist = std::hypot(o.pose.x - camera.x, o.pose.y - camera.y);
        if (t - o.t < options_.min_gap_s || dist > d) continue;
        if (std::fabs(common::wrapToPi(camera.phi - o.pose.phi)) > max_heading) continue;
        const double f = overlap(camera, v.ranges, o.pose, o.ranges);
        if (f >= options_.min_overlap) out.push_back({o.t, t, f, dist});
      }
    }
  std::sort(out.begin(), out.end(), [](const LoopPair& a, const LoopPair& b) { return a.t_old < b.t_old; });
  cells_[positionCellKey(camera.x, camera.y, d)].push_back(static_cast<uint32_t>(views_.size()));
  views_.push_back(std::move(v));
  return out;
}

}  // namespace urbanslam::sim
