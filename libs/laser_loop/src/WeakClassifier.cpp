#include "urbanslam/laser_loop/WeakClassifier.h"

#include <cmath>

namespace urbanslam::laser_loop {

void PairTable::add(const FeatureVector& a, const FeatureVector& b, bool match) {
  for (int k = 0; k < comparisons; ++k) c[k].push_back(compare(a, b, k));
  y.push_back(match ? 1 : 0);
}

StumpFit fitStump(const PairTable& data, int comparison, const std::vector<uint32_t>& order, const std::vector<double>& w) {
  const auto& c = data.c[comparison];
  double w_pos = 0, w_neg = 0;
  for (uint32_t i : order) (data.y[i] ? w_pos : w_neg) += w[i];
  const double total = w_pos + w_neg;
  // Cut k: the first k pairs of `order` lie below the threshold. With polarity +1 they are called
  // matches: error = negatives below + positives above. Polarity −1 is the complement.
  StumpFit best;
  best.error = 2 * total + 1;
  double neg_below = 0, pos_below = 0;
  const size_t n = order.size();
  if (n == 0) return best;
  for (size_t k = 0; k <= n; ++k) {
    if (k > 0) {
      const uint32_t i = order[k - 1];
      (data.y[i] ? pos_below : neg_below) += w[i];
    }
    if (k > 0 && k < n && !(c[order[k - 1]] < c[order[k]])) continue;  // not a cut between distinct values
    const double err_plus = neg_below + (w_pos - pos_below);
    const double err_minus = total - err_plus;
    double threshold;
    if (k == 0)
      threshold = c[order[0]] - 1.0;
    else if (k == n)
      threshold = c[order[n - 1]] + 1.0;
    else
      threshold = c[order[k - 1]] + 0.5 * (c[order[k]] - c[order[k - 1]]);
    if (err_plus < best.error) best = {{comparison, threshold, 1}, err_plus};
    if (err_minus < best.error) best = {{comparison, threshold, -1}, err_minus};
  }
  return best;
}

}  // namespace urbanslam::laser_loop
