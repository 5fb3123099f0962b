#pragma once
// How often a point in view of another scan lies where that scan's beams passed through, at poses
// that are right: people and doors that moved, glass, and outdoors the ground struck on slopes and
// vegetation a beam sometimes passes. Indoors it is a few in a thousand, outdoors a sizeable
// share; the free-space evidence of local matching (PriorScanMatcher.h, step 2') weighs a point
// seen through by it. Learnt from the matches whose scan agrees with the odometry, with a prior
// and a memory so that it follows the vehicle from one kind of place into another.
namespace urbanslam::alignment {

class SeenThroughRate {
 public:
  // prior_rate over prior_points; counts older than about memory_points points fade out.
  explicit SeenThroughRate(double prior_rate = 0.05, double prior_points = 200, double memory_points = 20000)
      : prior_seen_(prior_rate * prior_points), prior_points_(prior_points), memory_points_(memory_points) {}

  void add(int in_view, int seen_through) {
    if (in_view <= 0) return;
    points_ += in_view;
    seen_ += seen_through;
    if (points_ > memory_points_) {
      seen_ *= memory_points_ / points_;
      points_ = memory_points_;
    }
  }
  double rate() const { return (seen_ + prior_seen_) / (points_ + prior_points_); }

  // What was learnt (the prior and memory are the constructor's): for saving a run and taking
  // it up again where it stopped.
  double seenCount() const { return seen_; }
  double pointCount() const { return points_; }
  void restore(double seen, double points) {
    seen_ = seen;
    points_ = points;
  }

 private:
  double prior_seen_, prior_points_, memory_points_;
  double seen_ = 0, points_ = 0;
};

}  // namespace urbanslam::alignment
