#pragma once
// Places that one scan could not tell apart, told apart by the scans that follow. A place search
// answers only when its winner beats every other place by a margin per point
// (PlaceRecognizer.h); in a building of look-alike rooms and corridors one scan often leaves a
// few places within it. Each of them is then followed: carried scan by scan by the vehicle's
// motion (the same motion for all), and at each scan the pose near where the motion carried it
// that best explains the scan is searched on the map's coarse grid there (a small correlative
// window), its scan log-likelihood added to the place's total. When the vehicle moves on, the
// view changes, and the places part.
//
// Only the search's own winner can win: once its total leads every other place's by the
// search's margin per point (the points of the current scan), it is the answer, to be refined
// and checked as a search's winner is; a rival that leads it by that margin ends the following,
// and so do the winner leaving the map and max_duration_s passing. A rival that was not the best
// at the first scan is never promoted: where the vehicle stands in a place the map never saw,
// every place is wrong, and the one that trails least would otherwise be taken (on the raw
// benchmark logs that replaced correct poses with places metres away). The vehicle's own tracked
// pose may be one of the rivals (after local SLAM's view broke off, Localizer.h): it is
// replaced only if the search's winner leads it by the margin.
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/slam/MapAreas.h"
#include "urbanslam/slam/PlaceRecognizer.h"

namespace urbanslam::slam {

struct PlaceTrackingOptions {
  int max_places = 16;           // a search leaving more places than this is not followed (too little to go on)
  double window_m = 0.25;        // each place's pose searched within this of where the motion carried it ...
  double window_deg = 5.0;       // ... and within this of its heading
  double max_duration_s = 10.0;  // places followed this long with none winning are given up
};

class PlaceHypotheses {
 public:
  // `areas` and `places` must outlive this (the coarse grids and the margin, distinct_m and
  // distinct_deg of the search).
  PlaceHypotheses(MapAreas& areas, const PlaceRecognitionOptions& places, PlaceTrackingOptions options);

  // Follow these places from the scan of time t, whose search points are `points`: each is scored
  // again with them (within the window). Fewer than two, or more than max_places: nothing to do.
  void start(const std::vector<common::Pose2>& places, const std::vector<Eigen::Vector2d>& points, double t);
  void stop() { places_.clear(); }
  bool active() const { return !places_.empty(); }

  enum class Outcome { Following, Decided, GaveUp };
  // The next scan: `motion` the vehicle's motion since the previous one (in its frame). Decided:
  // the search's winner leads every rival by the margin, at winner().
  Outcome update(const common::Pose2& motion, const std::vector<Eigen::Vector2d>& points, double t);
  // The winning place's coarse pose at the last scan.
  const common::Pose2& winner() const { return winner_; }

 private:
  struct Place {
    common::Pose2 pose;
    double total = 0;  // scan log-likelihoods added since the start
  };
  // The best pose within the window around `pose` and its scan log-likelihood; false where the
  // map has no grid.
  bool score(const std::vector<Eigen::Vector2d>& points, Place& place);
  // Decided when the first place leads every other by the margin; GaveUp when one leads it so.
  Outcome decide(const std::vector<Eigen::Vector2d>& points);

  MapAreas& areas_;
  const PlaceRecognitionOptions& search_;
  PlaceTrackingOptions options_;
  std::vector<Place> places_;
  double started_ = 0;
  common::Pose2 winner_;
};

}  // namespace urbanslam::slam
