#pragma once
// How far the scan matches turn the odometry's heading, in units of the odometry model's own
// heading sigma: a configured noise model has to cover the worst odometry it will meet (an
// indoor robot's wheels), and a car's is several times better. The correlative search scans 3
// sigma of heading on each side (PriorScanMatcher.h), and its cost grows with that window; once
// enough matches have shown how large the corrections really are, a first search within
// kWindowRms times their RMS finds the same pose, and the prior's full window is searched only
// when that first match is in doubt (doubts()). The prior itself (the weights of odometry and
// scan) stays the configured one, so a match whose best pose lies inside the narrower window is
// the same match. Learnt with a memory, as SeenThroughRate is, so that it follows the vehicle
// onto other ground.
#include <algorithm>
#include <cmath>

namespace urbanslam::alignment {

class HeadingCorrections {
 public:
  static constexpr double kWindowRms = 5.0;      // the first window: this many RMS of the corrections
  static constexpr double kMinMatches = 50;      // before this many, the model's window alone
  static constexpr double kMemoryMatches = 200;  // older matches fade out
  static constexpr double kEdgeShare = 0.75;     // doubt: the best heading in the window's outer quarter
  static constexpr double kMatchedShare = 0.5;   // doubt: less than half the usual share of the scan matched

  // A match (from the model's full window, or not in doubt) turned the odometry's heading by
  // correction_rad, the model's sigma being sigma_rad, and matched this share of the scan.
  void add(double correction_rad, double sigma_rad, double matched_fraction) {
    if (!(sigma_rad > 0) || !std::isfinite(correction_rad) || !std::isfinite(matched_fraction)) return;
    const double z = correction_rad / sigma_rad;
    sum_squares_ += z * z;
    sum_matched_ += matched_fraction;
    matches_ += 1;
    if (matches_ > kMemoryMatches) {
      sum_squares_ *= kMemoryMatches / matches_;
      sum_matched_ *= kMemoryMatches / matches_;
      matches_ = kMemoryMatches;
    }
  }
  // The factor for the model's 3-sigma heading window of the first search: 1 (the model's
  // window, no second search) until enough matches were seen.
  double windowScale() const {
    if (matches_ < kMinMatches) return 1.0;
    return std::min(1.0, kWindowRms * std::sqrt(sum_squares_ / matches_) / 3.0);
  }
  // Whether a match from a narrowed window may have missed a better pose beyond it: its search's
  // best heading lies near the window's edge (the corrections are growing), or it explains far
  // less of the scan than the matches do (the true pose, and the fit, may lie outside). The
  // search's offset from the prior's mean and its half window, in radians.
  bool doubts(bool valid, double search_offset_rad, double half_window_rad, double matched_fraction) const {
    if (!valid) return true;
    if (std::abs(search_offset_rad) > kEdgeShare * half_window_rad) return true;
    return matches_ > 0 && matched_fraction < kMatchedShare * usualMatchedShare();
  }

  // The mean share of the scan the matches matched (0 before any).
  double usualMatchedShare() const { return matches_ > 0 ? sum_matched_ / matches_ : 0.0; }

  // What was learnt: for saving a run and taking it up again where it stopped.
  double sumSquares() const { return sum_squares_; }
  double sumMatched() const { return sum_matched_; }
  double matches() const { return matches_; }
  void restore(double sum_squares, double sum_matched, double matches) {
    sum_squares_ = sum_squares;
    sum_matched_ = sum_matched;
    matches_ = matches;
  }

 private:
  double sum_squares_ = 0;  // of the corrections over the model's sigma
  double sum_matched_ = 0;  // of the matched shares of the scans
  double matches_ = 0;
};

}  // namespace urbanslam::alignment
