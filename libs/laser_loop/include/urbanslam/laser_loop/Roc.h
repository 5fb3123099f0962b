#pragma once
// Receiver operating characteristic of a scored pair classifier: detection rate against false-
// alarm rate as the decision threshold (the strong classifier's factor, eq. 3.30) sweeps from 1
// down to 0. Scores are "higher = more alike"; a pair is called a match when score >= threshold.
#include <cstddef>
#include <vector>

namespace urbanslam::laser_loop {

struct RocPoint {
  double threshold = 0;
  double false_alarm = 0;  // fraction of non-matching pairs called matching
  double detection = 0;    // fraction of matching pairs called matching
};

struct OperatingPoint {
  double target_false_alarm = 0;
  double detection = 0;
  double false_alarm = 0;  // achieved (<= target)
  double threshold = 0;    // smallest threshold reaching it (match iff score >= threshold)
};

class Roc {
 public:
  Roc(std::vector<double> positive_scores, std::vector<double> negative_scores);

  // Highest detection rate with a false-alarm rate at most `fa` (0 allows no false alarm at all).
  OperatingPoint at(double fa) const;
  // One point per distinct threshold (thinned to at most max_points, keeping both ends).
  std::vector<RocPoint> curve(size_t max_points = 2000) const;
  double auc() const;
  size_t positives() const { return pos_.size(); }
  size_t negatives() const { return neg_.size(); }

 private:
  std::vector<double> pos_, neg_;  // sorted descending
};

}  // namespace urbanslam::laser_loop
