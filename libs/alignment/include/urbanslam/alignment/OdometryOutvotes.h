#pragma once
// How often a scan match outvotes the odometry (its pose lies outside the odometry's Gaussian,
// PriorScanMatcher.h): on the raw benchmark logs from 1 in 500 matches (Intel) to 1 in 10
// (FR079's reversals reported as driving forwards, Victoria Park's steering model), in the
// simulated cities never. Where it stays rare the odometry can be trusted to its Gaussian: local
// matching first searches the window the Gaussian spans, and the window that covers odometry
// wrong in direction only when that match is in doubt (LocalSubmap.h). A share learnt with a
// prior that starts distrustful and a memory, counted as SeenThroughRate counts its points (each
// match one trial), so that it follows the vehicle onto other ground.
#include "urbanslam/alignment/SeenThroughRate.h"

namespace urbanslam::alignment {

class OdometryOutvotes {
 public:
  static constexpr double kTrustedRate = 0.01;   // trusted below one outvote in a hundred matches
  static constexpr double kPriorRate = 0.05;     // the prior: one outvote in ...
  static constexpr double kPriorMatches = 20;    // ... twenty matches (trusted after some eighty clean ones)
  static constexpr double kMemoryMatches = 500;  // older matches fade out

  void add(bool outvoted) { share_.add(1, outvoted ? 1 : 0); }
  double rate() const { return share_.rate(); }
  bool trusted() const { return rate() < kTrustedRate; }

  // What was learnt: for saving a run and taking it up again where it stopped.
  double outvotes() const { return share_.seenCount(); }
  double matches() const { return share_.pointCount(); }
  void restore(double outvotes, double matches) { share_.restore(outvotes, matches); }

 private:
  SeenThroughRate share_{kPriorRate, kPriorMatches, kMemoryMatches};
};

}  // namespace urbanslam::alignment
