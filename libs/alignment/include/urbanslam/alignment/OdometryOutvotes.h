#pragma once
// How often a scan match outvotes the odometry (its pose lies outside the odometry's Gaussian,
// PriorScanMatcher.h): on the raw benchmark logs from 1 in 500 matches (Intel) to 1 in 10
// (FR079's reversals reported as driving forwards, Victoria Park's steering model), in the
// simulated cities never. Where it stays rare the odometry can be trusted to its Gaussian: local
// matching first searches the window the Gaussian spans, and the window that covers odometry
// wrong in direction only when that match is in doubt (LocalSubmap.h). A share learnt with a
// prior that starts distrustful and a memory, counted as SeenThroughRate counts its points (each
// match one trial), so that it follows the vehicle onto other ground.
#include <cmath>

#include "urbanslam/alignment/SeenThroughRate.h"

namespace urbanslam::alignment {

class OdometryOutvotes {
 public:
  static constexpr double kTrustedRate = 0.01;   // trusted below one outvote in a hundred matches
  static constexpr double kPriorRate = 0.05;     // the prior: one outvote in ...
  static constexpr double kPriorMatches = 20;    // ... twenty matches (trusted after some eighty clean ones)
  static constexpr double kMemoryMatches = 500;  // older matches fade out

  static constexpr double kEdgeShare = 0.75;    // doubt: the best translation in the window's outer quarter
  static constexpr double kMatchedShare = 0.9;  // doubt: under this share of the usual share of the scan matched

  void add(bool outvoted) { share_.add(1, outvoted ? 1 : 0); }
  double rate() const { return share_.rate(); }
  bool trusted() const { return rate() < kTrustedRate; }

  // Whether a match searched within the trusted odometry's window (half_width_m each way of the
  // odometry's pose) is in doubt, so that the window covering odometry wrong in direction must be
  // searched: its best translation (offset from the odometry's) in the window's outer quarter on
  // either axis, the odometry outvoted, or under kMatchedShare of the usual share of the scan
  // matched (what every match the full window moved beyond the narrower one showed on FR079 and
  // Victoria Park).
  static bool doubtsNarrowMatch(double offset_x_m, double offset_y_m, double half_width_m, bool outvoted, double matched_share,
                                double usual_matched_share) {
    const double edge = kEdgeShare * half_width_m;
    return std::abs(offset_x_m) > edge || std::abs(offset_y_m) > edge || outvoted || matched_share < kMatchedShare * usual_matched_share;
  }

  // What was learnt: for saving a run and taking it up again where it stopped.
  double outvotes() const { return share_.seenCount(); }
  double matches() const { return share_.pointCount(); }
  void restore(double outvotes, double matches) { share_.restore(outvotes, matches); }

 private:
  SeenThroughRate share_{kPriorRate, kPriorMatches, kMemoryMatches};
};

}  // namespace urbanslam::alignment
