#include "urbanslam/slam/PlaceHypotheses.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/alignment/CorrelativeSearch.h"
#include "urbanslam/alignment/MotionPrior.h"

namespace urbanslam::slam {

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

PlaceHypotheses::PlaceHypotheses(MapAreas& areas, const PlaceRecognitionOptions& places, PlaceTrackingOptions options)
    : areas_(areas), search_(places), options_(options) {}

bool PlaceHypotheses::score(const std::vector<Eigen::Vector2d>& points, Place& place) {
  const alignment::LikelihoodGrid* grid = areas_.coarseGrid(place.pose.x, place.pose.y);
  if (!grid) return false;
  alignment::CorrelativeWindow window;
  window.half_width_m = options_.window_m;
  window.half_angle_rad = options_.window_deg * kDeg;
  window.flat_prior = true;
  // No prior within the window: the same flat density as the place search's, so that the scores
  // compare with each other and with the search's.
  const alignment::MotionPrior prior(place.pose, Eigen::Vector3d(1e8, 1e8, 1e8).asDiagonal(), 0.0, 1.0);
  const alignment::CorrelativeResult r = alignment::correlativeSearch(*grid, points, prior, window);
  place.pose = r.pose;
  place.total += r.scan_score;
  return true;
}

void PlaceHypotheses::start(const std::vector<common::Pose2>& places, const std::vector<Eigen::Vector2d>& points, double t) {
  places_.clear();
  if (places.size() < 2 || places.size() > static_cast<size_t>(options_.max_places)) return;
  for (const common::Pose2& pose : places) {
    Place p{pose, 0};
    if (score(points, p))
      places_.push_back(p);
    else if (places_.empty())
      return;  // the winner itself off the grids
  }
  if (places_.size() < 2) places_.clear();
  started_ = t;
}

PlaceHypotheses::Outcome PlaceHypotheses::decide(const std::vector<Eigen::Vector2d>& points) {
  // The search's winner (first) against its rivals: a rival that leads it by the margin ends the
  // following; a lead of the margin over every rival decides it.
  const double margin = search_.min_margin_per_point * static_cast<double>(points.size());
  const Place& best = places_.front();
  bool clear = true;
  for (size_t i = 1; i < places_.size(); ++i) {
    if (!distinctPlaces(places_[i].pose, best.pose, search_)) continue;  // converged onto the winner
    if (places_[i].total - best.total >= margin) {
      places_.clear();
      return Outcome::GaveUp;
    }
    if (best.total - places_[i].total < margin) clear = false;
  }
  if (!clear) return Outcome::Following;
  winner_ = best.pose;
  places_.clear();
  return Outcome::Decided;
}

PlaceHypotheses::Outcome PlaceHypotheses::update(const common::Pose2& motion, const std::vector<Eigen::Vector2d>& points, double t) {
  if (places_.empty()) return Outcome::GaveUp;
  if (t - started_ > options_.max_duration_s) {
    places_.clear();
    return Outcome::GaveUp;
  }
  for (Place& p : places_) p.pose = common::compose(p.pose, motion);
  if (static_cast<int>(points.size()) < search_.min_points) return Outcome::Following;  // a scan too sparse to tell places apart
  std::vector<Place> moved;
  for (size_t i = 0; i < places_.size(); ++i) {
    Place p = places_[i];
    if (score(points, p))
      moved.push_back(p);
    else if (i == 0) {  // the winner carried off the map
      places_.clear();
      return Outcome::GaveUp;
    }  // a rival carried off the map is out
  }
  places_ = std::move(moved);
  if (places_.size() < 2) {
    places_.clear();
    return Outcome::GaveUp;
  }
  return decide(points);
}

}  // namespace urbanslam::slam
