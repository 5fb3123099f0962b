#pragma once
// Whether a localizer still knows where it is, from its last few scans (a sliding window): each
// scan's match either failed (too few points, or too few of them explained by the map) or gave
// a correction of the prediction whose normalised squared size d' P⁻¹ d (P the covariance of
// the correction: the prediction's plus the match's own, Localizer.cpp) is chi-square
// distributed, 3 degrees of freedom, while the matches agree with the odometry. Lost: more than
// half of the window's matches failed, or the window's corrections together fail the chi-square
// test (sum over k matches against the quantile for 3k degrees of freedom). One bad scan (a
// person in front of the laser, an odometry jolt) is absorbed; a run of them is not. Each
// scan's term is capped at the one-scan quantile, so a single wild correction cannot decide on
// its own.
#include <deque>
#include <vector>

namespace urbanslam::slam {

struct TrackingMonitorOptions {
  int window_scans = 10;
  double probability = 0.999;  // of the chi-square tests (one scan's cap, the window's sum)
};

class TrackingMonitor {
 public:
  explicit TrackingMonitor(TrackingMonitorOptions options);
  void reset();
  // A match that explained the scan, its correction's d' P⁻¹ d (3 dof).
  void addMatch(double mahalanobis2);
  void addFailure();
  bool lost() const;
  // The window's sum and its threshold (for diagnostics).
  double windowSum() const;
  double windowThreshold() const;

 private:
  struct Entry {
    bool matched;
    double term;
  };
  void push(Entry e);
  TrackingMonitorOptions options_;
  double cap_;
  std::vector<double> thresholds_;  // by the number of matches in the window
  std::deque<Entry> window_;
};

}  // namespace urbanslam::slam
