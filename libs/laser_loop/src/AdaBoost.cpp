#include "urbanslam/laser_loop/AdaBoost.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "urbanslam/common/Error.h"

namespace urbanslam::laser_loop {

AdaBoostTrainer::AdaBoostTrainer(const PairTable& data, std::vector<uint32_t> subset, bool trace_weights)
    : data_(data), subset_(std::move(subset)), trace_(trace_weights) {
  if (subset_.empty()) {
    subset_.resize(data.size());
    std::iota(subset_.begin(), subset_.end(), 0u);
  }
  size_t n_pos = 0;
  for (uint32_t i : subset_) n_pos += data.y[i];
  const size_t n_neg = subset_.size() - n_pos;
  if (n_pos == 0 || n_neg == 0)
    throw common::InputError("AdaBoost needs both matching and non-matching pairs (got " + std::to_string(n_pos) + " positive, " +
                             std::to_string(n_neg) + " negative)");
  w_.assign(data.size(), 0.0);
  for (uint32_t i : subset_) w_[i] = data.y[i] ? 1.0 / (2.0 * n_pos) : 1.0 / (2.0 * n_neg);
  // c does not change between rounds, only the weights: sort once per comparison.
  order_.resize(static_cast<size_t>(data.comparisons));
  for (int f = 0; f < data.comparisons; ++f) {
    order_[f] = subset_;
    const auto& c = data.c[f];
    std::stable_sort(order_[f].begin(), order_[f].end(), [&c](uint32_t a, uint32_t b) { return c[a] < c[b]; });
  }
  w_subset_.resize(subset_.size());
  for (size_t k = 0; k < subset_.size(); ++k) w_subset_[k] = w_[subset_[k]];
}

bool AdaBoostTrainer::round() {
  if (finished_) return false;
  // 2: normalise (3.27).
  double sum = 0;
  for (uint32_t i : subset_) sum += w_[i];
  for (uint32_t i : subset_) w_[i] /= sum;
  // 3–4: best stump over all comparisons (3.28); ties keep the lowest index.
  StumpFit best;
  best.error = 2.0;
  for (int f = 0; f < data_.comparisons; ++f) {
    const StumpFit fit = fitStump(data_, f, order_[f], w_);
    if (fit.error < best.error) best = fit;
  }
  // ε from the chosen stump's own decisions, exactly Σ W̃ |c − y|.
  double eps = 0;
  for (uint32_t i : subset_) {
    const bool e = best.stump.match(data_.c[best.stump.comparison][i]) != (data_.y[i] != 0);
    if (e) eps += w_[i];
  }
  BoostRound r;
  if (trace_) {
    r.normalised_weights.resize(subset_.size());
    for (size_t k = 0; k < subset_.size(); ++k) r.normalised_weights[k] = w_[subset_[k]];
  }
  if (eps >= 0.5) {
    finished_ = true;
    return false;
  }
  const double eps_used = std::max(eps, 1e-10);
  const double beta = eps_used / (1.0 - eps_used);
  r.chosen = {best.stump, std::log(1.0 / beta)};
  r.error = eps;
  r.beta = eps > 0 ? beta : 0.0;
  // 5: W_{t+1} = W̃_t β^{1 − e_i}: correctly classified pairs are scaled down.
  if (eps > 0) {
    for (uint32_t i : subset_) {
      const bool e = best.stump.match(data_.c[best.stump.comparison][i]) != (data_.y[i] != 0);
      if (!e) w_[i] *= beta;
    }
  } else {
    finished_ = true;
  }
  for (size_t k = 0; k < subset_.size(); ++k) w_subset_[k] = w_[subset_[k]];
  stumps_.push_back(r.chosen);
  classifier_ = StrongClassifier(stumps_);
  rounds_.push_back(std::move(r));
  return true;
}

StrongClassifier trainAdaBoost(const PairTable& data, const std::vector<uint32_t>& subset, int T) {
  AdaBoostTrainer trainer(data, subset);
  trainer.run(T);
  return trainer.classifier();
}

}  // namespace urbanslam::laser_loop
