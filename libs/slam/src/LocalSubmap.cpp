#include "urbanslam/slam/LocalSubmap.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/alignment/ScanModel.h"

namespace urbanslam::slam {

alignment::PriorMatcherOptions priorMatcherOptions(const LocalOptions& o) {
  alignment::PriorMatcherOptions m;
  m.grid.resolution_m = o.resolution_m;
  m.grid.hit_sigma_m = o.hit_sigma_m;
  m.grid.miss_floor = o.miss_floor;
  m.grid.max_radius_m = o.grid_radius_m;
  m.voxel_m = o.voxel_m;
  m.search_window_m = o.search_window_m;
  m.search_window_deg = o.search_window_deg;
  m.odometry_outlier_probability = o.odometry_outlier_probability;
  m.point_sigma_m = o.point_sigma_m;
  return m;
}

LocalSubmap::LocalSubmap(const LocalOptions& options)
    : matcher_(priorMatcherOptions(options)), capacity_(static_cast<size_t>(std::max(1, options.submap_keyframes))) {}

alignment::PointSet LocalSubmap::points(const io::LaserScan& scan) const {
  // The alignment module's scan model, in the vehicle frame (the scan's sensor pose applied).
  return alignment::pointSetFromScan(scan, scan_model_, true);
}

void LocalSubmap::addKeyframe(const io::LaserScan& scan) {
  sets_.push_back(points(scan));
  beams_.emplace_back(sets_.back(), matcher_.free_margin_m, matcher_.free_margin_fraction);
  while (sets_.size() > capacity_) {
    sets_.pop_front();
    beams_.pop_front();
  }
  ++generation_;
}

const alignment::MatchReference* LocalSubmap::reference(const std::vector<common::Pose2>& poses) const {
  std::vector<common::Pose2> offsets;
  for (const auto& p : poses) offsets.push_back(common::between(poses.back(), p));
  const auto same = [](const common::Pose2& a, const common::Pose2& b) { return a.x == b.x && a.y == b.y && a.phi == b.phi; };
  if (cache_.generation == generation_ && cache_.offsets.size() == offsets.size() &&
      std::equal(offsets.begin(), offsets.end(), cache_.offsets.begin(), same))
    return cache_.reference.get();
  alignment::PointSet points;
  size_t total = 0;
  for (const auto& set : sets_) total += set.size();
  points.reserve(total);
  std::vector<alignment::ReferenceView> views;
  for (size_t i = 0; i < sets_.size(); ++i) {
    alignment::appendTransformed(sets_[i], offsets[i], &points);
    views.push_back({beams_[i], offsets[i]});
  }
  cache_.generation = generation_;
  cache_.offsets = std::move(offsets);
  cache_.reference = points.empty() ? nullptr
                                    : std::make_unique<const alignment::MatchReference>(std::move(points), Eigen::Vector2d::Zero(),
                                                                                        matcher_, std::move(views));
  return cache_.reference.get();
}

alignment::PriorMatchResult LocalSubmap::match(const io::LaserScan& scan, const common::Pose2& prior, const Eigen::Matrix3d& prior_cov,
                                               const std::vector<common::Pose2>& poses, double direction_reach_m) const {
  alignment::PriorMatchResult none;
  none.pose = prior;
  none.cov = prior_cov;
  if (poses.size() != sets_.size() || sets_.empty()) {
    none.failure_reason = "no submap";
    return none;
  }
  const alignment::MatchReference* ref = reference(poses);
  if (!ref) {
    none.failure_reason = "empty submap";
    return none;
  }
  alignment::PriorMatcherOptions options = matcher_;
  options.seen_through_rate = seen_through_.rate();
  options.seen_through_rate_displaced = seen_through_displaced_.rate();
  options.direction_reach_m = direction_reach_m;
  const alignment::PointSet scan_points = points(scan);
  // The narrowest search the evidence does not doubt. Where the odometry has held to its Gaussian
  // (OdometryOutvotes.h): within the heading corrections' reach and the prior's 3σ of
  // translation. Otherwise the search over the heading corrections' reach and the translation
  // that covers odometry wrong in direction (twice the travel: the window of a car at 10 m/s 4 m
  // square). The prior's full window when a search's match is in doubt (not when no search ran:
  // too few points fail the same way in any window): its heading (HeadingCorrections::doubts)
  // or, with the direction's reach left out, its translation
  // (OdometryOutvotes::doubtsNarrowMatch).
  const double usual = heading_corrections_.usualMatchedShare();
  const bool trusted = outvotes_.trusted();
  options.heading_window_scale = heading_corrections_.windowScale();
  options.search_direction_reach = !trusted;
  alignment::PriorMatchResult r = alignment::matchWithPrior(*ref, scan_points, prior, prior_cov, options);
  const bool poor = !options.search_direction_reach &&
                    alignment::OdometryOutvotes::doubtsNarrowMatch(r.search_pose.x - prior.x, r.search_pose.y - prior.y,
                                                                   r.search_half_width_m, r.odometry_outvoted, r.matchedFraction(), usual);
  if (r.window_narrowed && r.search_nodes > 0 &&
      (poor || heading_corrections_.doubts(r.valid, common::wrapToPi(r.search_pose.phi - prior.phi), r.search_half_angle_rad,
                                           r.matchedFraction()))) {
    options.heading_window_scale = 1;
    options.search_direction_reach = true;
    r = alignment::matchWithPrior(*ref, scan_points, prior, prior_cov, options);
  }
  if (r.valid) outvotes_.add(r.odometry_outvoted);
  if (r.valid && !r.odometry_outvoted) {
    heading_corrections_.add(common::wrapToPi(r.pose.phi - prior.phi), std::sqrt(prior_cov(2, 2)), r.matchedFraction());
    seen_through_.add(r.in_view, r.seen_through);
    seen_through_displaced_.add(r.displaced_in_view, r.displaced_seen_through);
  }
  return r;
}

}  // namespace urbanslam::slam
