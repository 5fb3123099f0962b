#pragma once
// The strong classifier of eq. 3.30: a pair matches when Σ α_t c_t ≥ factor · Σ α_t, where c_t is
// the 0/1 decision of stump t and α_t = log(1/β_t). The thesis prints the factor as 0.5 and notes
// it can be moved to trade detection for false alarm; `score` returns the normalised vote
// Σ α_t c_t / Σ α_t in [0, 1] so a ROC is a sweep of the factor over the scores.
//
// (The extracted thesis text shows "≤" in 3.30; with c_t = 1 meaning "match", as eq. 3.28 |c − y|
// requires, only "≥" makes a vote of matching stumps a match — the form of Freund & Schapire and
// Viola & Jones that Algorithm 1 follows.)
#include <vector>

#include "urbanslam/laser_loop/WeakClassifier.h"

namespace urbanslam::laser_loop {

struct WeightedStump {
  Stump stump;
  double alpha = 0;
};

class StrongClassifier {
 public:
  StrongClassifier() = default;
  explicit StrongClassifier(std::vector<WeightedStump> stumps);

  const std::vector<WeightedStump>& stumps() const { return stumps_; }
  size_t size() const { return stumps_.size(); }
  // The classifier made of the first T stumps (AdaBoost's classifier after T rounds).
  StrongClassifier prefix(size_t T) const;

  // Σ α_t c_t / Σ α_t (0 for an empty classifier).
  double score(const FeatureVector& a, const FeatureVector& b) const;
  bool match(const FeatureVector& a, const FeatureVector& b, double factor = 0.5) const {
    return score(a, b) >= factor;
  }

 private:
  // Compact branch-free form for score(): stump outcomes are data-dependent coin flips to the
  // branch predictor, so each vote is computed as arithmetic instead.
  struct Compiled {
    int feature;
    double signed_threshold_sign;  // polarity
    double threshold;
    double alpha;
  };
  std::vector<WeightedStump> stumps_;
  std::vector<Compiled> compiled_;
  double alpha_total_ = 0;
};

}  // namespace urbanslam::laser_loop
