#include "urbanslam/slam/PlaceRecognizer.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "urbanslam/alignment/CorrelativeSearch.h"
#include "urbanslam/alignment/MotionPrior.h"
#include "urbanslam/alignment/Voxels.h"

namespace urbanslam::slam {

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

bool distinctPlaces(const common::Pose2& a, const common::Pose2& b, const PlaceRecognitionOptions& options) {
  return std::hypot(a.x - b.x, a.y - b.y) > options.distinct_m || std::abs(common::wrapToPi(a.phi - b.phi)) > options.distinct_deg * kDeg;
}

PlaceRecognizer::PlaceRecognizer(const Map& map, MapAreas& areas, PlaceRecognitionOptions options)
    : areas_(areas), options_(std::move(options)) {
  const double s = options_.candidate_spacing_m;
  std::set<std::pair<int64_t, int64_t>> cells;
  for (const Keyframe& k : map.keyframes())
    if (k.hasScan() && std::isfinite(k.pose.x) && std::isfinite(k.pose.y))
      cells.insert({static_cast<int64_t>(std::floor(k.pose.x / s)), static_cast<int64_t>(std::floor(k.pose.y / s))});
  for (const auto& [cx, cy] : cells) centres_.emplace_back((static_cast<double>(cx) + 0.5) * s, (static_cast<double>(cy) + 0.5) * s);
  // Grouped by tile, so one search builds (or fetches) each tile's grid once.
  std::stable_sort(centres_.begin(), centres_.end(), [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return areas_.tileKey(a.x(), a.y()) < areas_.tileKey(b.x(), b.y());
  });
}

PlaceHypothesis PlaceRecognizer::locate(const alignment::PointSet& scan, const alignment::PriorMatcherOptions& matcher,
                                        const std::vector<PlaceSearchRegion>& regions) {
  PlaceHypothesis h;
  const std::vector<Eigen::Vector2d> points = searchPoints(scan);
  h.points = static_cast<int>(points.size());
  if (h.points < options_.min_points) {
    h.reason = "too few points";
    return h;
  }
  alignment::CorrelativeWindow window;
  window.half_width_m = options_.candidate_spacing_m / 2 + options_.window_overlap_m;
  window.half_angle_rad = M_PI;
  window.flat_prior = true;
  // No prior: a Gaussian so wide that its density is flat over any window.
  const Eigen::Matrix3d flat = Eigen::Vector3d(1e8, 1e8, 1e8).asDiagonal();
  struct Found {
    common::Pose2 pose;
    double score;
  };
  // A window reaches into a region when its centre does once the region's covariance is
  // widened by the window's half diagonal.
  std::vector<Eigen::Matrix2d> region_inverse;
  const double reach = window.half_width_m * M_SQRT2;
  for (const PlaceSearchRegion& r : regions) region_inverse.push_back((r.cov + reach * reach * Eigen::Matrix2d::Identity()).inverse());
  const auto withinReach = [&](const Eigen::Vector2d& c) {
    for (size_t k = 0; k < regions.size(); ++k) {
      const Eigen::Vector2d d = c - regions[k].centre;
      if (d.dot(region_inverse[k] * d) <= regions[k].gate) return true;
    }
    return regions.empty();
  };
  std::vector<Found> found;
  // Only poses within the margin of the best so far can win or make the winner ambiguous: each
  // window is searched for those only (the prior's log-density, flat, as the search takes it).
  double best_scan = -HUGE_VAL;
  const double margin = options_.min_margin_per_point * static_cast<double>(points.size());
  // The windows within reach of the regions (every window without any).
  std::vector<Eigen::Vector2d> windows;
  std::set<std::pair<int64_t, int64_t>> searched;
  const auto cellOf = [&](const Eigen::Vector2d& c) {
    return std::make_pair(static_cast<int64_t>(std::floor(c.x() / options_.candidate_spacing_m)),
                          static_cast<int64_t>(std::floor(c.y() / options_.candidate_spacing_m)));
  };
  for (const Eigen::Vector2d& c : centres_) {
    if (!withinReach(c)) continue;
    windows.push_back(c);
    searched.insert(cellOf(c));
  }
  for (const Eigen::Vector2d& c : windows) {
    const alignment::LikelihoodGrid* grid = areas_.coarseGrid(c.x(), c.y());
    if (!grid) continue;
    // A window reaches window_overlap_m into each neighbouring cell, for the poses near the
    // visited cells; where the neighbour is searched itself, its own window covers those poses
    // (the same lattice of poses and headings, the window centres lying a whole number of grid
    // cells apart), and searching them twice only cost time (a quarter of the place search).
    const auto [cx, cy] = cellOf(c);
    const double t = options_.window_overlap_m;
    window.trim_m = {searched.count({cx - 1, cy}) ? t : 0.0, searched.count({cx + 1, cy}) ? t : 0.0, searched.count({cx, cy - 1}) ? t : 0.0,
                     searched.count({cx, cy + 1}) ? t : 0.0};
    const alignment::MotionPrior prior({c.x(), c.y(), 0.0}, flat, 0.0, 1.0);
    window.min_score = best_scan - margin + prior.logDensity(0.0);
    const alignment::CorrelativeResult r = alignment::correlativeSearch(*grid, points, prior, window);
    h.nodes += r.nodes;
    ++h.candidates;
    if (r.below_min_score) continue;
    found.push_back({r.pose, r.scan_score});
    best_scan = std::max(best_scan, r.scan_score);
  }
  if (found.empty()) {
    h.reason = regions.empty() ? "empty map" : "no mapped place within reach";
    return h;
  }
  const auto best = std::max_element(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.score < b.score; });
  h.score = best->score;
  h.second_score = -std::numeric_limits<double>::infinity();
  for (const Found& f : found) {
    if (distinctPlaces(f.pose, best->pose, options_)) h.second_score = std::max(h.second_score, f.score);
  }
  h.margin_per_point = (h.score - h.second_score) / h.points;  // +inf when the map has one place only
  h.pose = best->pose;
  if (h.margin_per_point < options_.min_margin_per_point) {
    h.reason = "ambiguous";
    // The places within the margin, one per place: best first, each distinct from every one kept.
    std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.score > b.score; });
    for (const Found& f : found) {
      if (f.score < h.score - margin) break;
      const bool distinct =
          std::all_of(h.places.begin(), h.places.end(), [&](const common::Pose2& p) { return distinctPlaces(f.pose, p, options_); });
      if (distinct) h.places.push_back(f.pose);
    }
    return h;
  }
  return refine(scan, best->pose, matcher, std::move(h));
}

std::vector<Eigen::Vector2d> PlaceRecognizer::searchPoints(const alignment::PointSet& scan) const {
  alignment::PointSet near;
  for (const auto& sp : scan)
    if (sp.p.norm() <= options_.max_range_m) near.push_back(sp);
  std::vector<Eigen::Vector2d> points;
  for (const size_t i : alignment::firstPerVoxel(near, options_.voxel_m)) points.push_back(near[i].p);
  return points;
}

PlaceHypothesis PlaceRecognizer::refine(const alignment::PointSet& scan, const common::Pose2& coarse,
                                        const alignment::PriorMatcherOptions& matcher, PlaceHypothesis h) {
  h.pose = coarse;
  // The winner refined on the fine reference, from the coarse pose.
  const alignment::MatchReference* reference = areas_.reference(coarse.x, coarse.y);
  if (!reference) {
    h.reason = "no reference";
    return h;
  }
  const double s = options_.refine_sigma_m, a = options_.refine_sigma_deg * kDeg;
  const alignment::PriorMatchResult r =
      alignment::matchWithPrior(*reference, scan, coarse, Eigen::Vector3d(s * s, s * s, a * a).asDiagonal(), matcher);
  h.matched_fraction = r.matchedFraction();
  if (!r.valid) {
    h.reason = "refinement failed: " + r.failure_reason;
    return h;
  }
  if (h.matched_fraction < options_.min_matched_fraction) {
    h.reason = "poor fit";
    return h;
  }
  h.seen_through_share = r.in_view > 0 ? static_cast<double>(r.seen_through) / r.in_view : 1.0;
  const double max_share =
      h.margin_per_point >= options_.clear_margin_per_point ? options_.max_seen_through_share_clear : options_.max_seen_through_share;
  if (h.seen_through_share > max_share) {
    h.reason = "walls where the other side saw free space";
    return h;
  }
  h.found = true;
  h.pose = r.pose;
  h.cov = r.cov;
  return h;
}

}  // namespace urbanslam::slam
