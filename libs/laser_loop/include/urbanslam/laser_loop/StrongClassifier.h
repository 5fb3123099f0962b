#pragma once
// The strong classifier of eq. 3.30: a pair matches when Σ α_t c_t ≥ factor · Σ α_t, where c_t is
// the 0/1 decision of stump t and α_t = log(1/β_t). The thesis prints the factor as 0.5 and notes
// it can be moved to trade detection for false alarm; `score` returns the normalised vote
// Σ α_t c_t / Σ α_t in [0, 1] so a ROC is a sweep of the factor over the scores.
//
// (The extracted thesis text shows "≤" in 3.30; with c_t = 1 meaning "match", as eq. 3.28 |c − y|
// requires, only "≥" makes a vote of matching stumps a match — the form of Freund & Schapire and
// Viola & Jones that Algorithm 1 follows.)
#include <cstdint>
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
  bool match(const FeatureVector& a, const FeatureVector& b, double factor = 0.5) const { return score(a, b) >= factor; }

 private:
  // score() form: per comparison used, its stumps' thresholds sorted, with the α sums of the stumps
  // that vote "match" above (polarity +1) or below (polarity −1) each cut. A vote is then one
  // comparison and a branch-free count of thresholds per comparison (stump outcomes are coin flips to a
  // branch predictor), with everything in flat arrays.
  struct FeatureVotes {
    int comparison = 0;
    uint32_t plus_begin = 0, plus_count = 0;    // into thr_; alpha_ has plus_count + 1 entries
    uint32_t minus_begin = 0, minus_count = 0;  // into thr_; alpha_ has minus_count + 1 entries
    uint32_t plus_alpha = 0, minus_alpha = 0;   // into alpha_
  };
  std::vector<WeightedStump> stumps_;
  std::vector<FeatureVotes> votes_;
  std::vector<double> thr_;    // sorted ascending within each run
  std::vector<double> alpha_;  // +1: α of stumps with threshold > c, indexed by #thresholds <= c
                               // −1: α of stumps with threshold < c, indexed by #thresholds < c
  double alpha_total_ = 0;
};

}  // namespace urbanslam::laser_loop
