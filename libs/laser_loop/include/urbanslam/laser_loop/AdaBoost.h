#pragma once
// AdaBoost exactly as the thesis's Algorithm 1 (after Freund & Schapire / Viola & Jones):
//   W_1 = 1/(2 N_n) for negative pairs, 1/(2 N_p) for positive pairs;
//   for t = 1..T: normalise (3.27); fit a stump per feature and take the one with the least
//   weighted error ε_t (3.28); β_t = ε_t / (1 − ε_t); W_{t+1} = W̃_t β_t^{1 − e_i} (3.29), e_i = 0
//   for a correctly classified pair; α_t = log(1/β_t).
// Two edge cases Algorithm 1 leaves open: ε_t = 0 (a perfect stump: β = 0, α = ∞) adds the stump
// with α computed from ε = 1e-10 and ends training, since every weight but the (absent) errors
// would become 0; ε_t ≥ 0.5 (no stump better than chance) ends training without adding it.
#include <cstdint>
#include <vector>

#include "urbanslam/laser_loop/StrongClassifier.h"

namespace urbanslam::laser_loop {

struct BoostRound {
  WeightedStump chosen;
  double error = 0;                        // ε_t
  double beta = 0;                         // β_t
  std::vector<double> normalised_weights;  // W̃_t over the training subset (only when traced)
};

class AdaBoostTrainer {
 public:
  // Trains on the pairs `subset` of `data` (all pairs when empty). Needs both classes.
  AdaBoostTrainer(const PairTable& data, std::vector<uint32_t> subset, bool trace_weights = false);

  // One round of Algorithm 1; false (and nothing added) once training has ended.
  bool round();
  void run(int T) {
    for (int t = 0; t < T && round(); ++t) {
    }
  }
  bool finished() const { return finished_; }

  const StrongClassifier& classifier() const { return classifier_; }
  const std::vector<BoostRound>& rounds() const { return rounds_; }
  // Current (unnormalised) weights W_{t+1}, indexed like the subset.
  const std::vector<double>& weights() const { return w_subset_; }
  const std::vector<uint32_t>& subset() const { return subset_; }

 private:
  const PairTable& data_;
  std::vector<uint32_t> subset_;
  std::vector<std::vector<uint32_t>> order_;  // per feature: subset sorted by c
  std::vector<double> w_;                     // indexed like the table (only subset entries used)
  std::vector<double> w_subset_;
  bool trace_;
  bool finished_ = false;
  StrongClassifier classifier_;
  std::vector<WeightedStump> stumps_;
  std::vector<BoostRound> rounds_;
};

StrongClassifier trainAdaBoost(const PairTable& data, const std::vector<uint32_t>& subset, int T);

}  // namespace urbanslam::laser_loop
