#include "urbanslam/laser_loop/StrongClassifier.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::laser_loop {

StrongClassifier::StrongClassifier(std::vector<WeightedStump> stumps) : stumps_(std::move(stumps)) {
  std::vector<int> slot(kComparisonCount, -1);
  std::vector<std::vector<std::pair<double, double>>> plus, minus;  // (threshold, α) per comparison
  for (const auto& s : stumps_) {
    alpha_total_ += s.alpha;
    int& k = slot[s.stump.comparison];
    if (k < 0) {
      k = static_cast<int>(votes_.size());
      votes_.push_back({});
      votes_.back().comparison = s.stump.comparison;
      plus.emplace_back();
      minus.emplace_back();
    }
    (s.stump.polarity > 0 ? plus : minus)[static_cast<size_t>(k)].emplace_back(s.stump.threshold, s.alpha);
  }
  for (size_t k = 0; k < votes_.size(); ++k) {
    auto& v = votes_[k];
    std::sort(plus[k].begin(), plus[k].end());
    std::sort(minus[k].begin(), minus[k].end());
    v.plus_begin = static_cast<uint32_t>(thr_.size());
    v.plus_count = static_cast<uint32_t>(plus[k].size());
    for (const auto& [t, a] : plus[k]) thr_.push_back(t);
    v.minus_begin = static_cast<uint32_t>(thr_.size());
    v.minus_count = static_cast<uint32_t>(minus[k].size());
    for (const auto& [t, a] : minus[k]) thr_.push_back(t);
    v.plus_alpha = static_cast<uint32_t>(alpha_.size());
    std::vector<double> above(plus[k].size() + 1, 0.0);
    for (size_t i = plus[k].size(); i-- > 0;) above[i] = above[i + 1] + plus[k][i].second;
    alpha_.insert(alpha_.end(), above.begin(), above.end());
    v.minus_alpha = static_cast<uint32_t>(alpha_.size());
    std::vector<double> below(minus[k].size() + 1, 0.0);
    for (size_t i = 0; i < minus[k].size(); ++i) below[i + 1] = below[i] + minus[k][i].second;
    alpha_.insert(alpha_.end(), below.begin(), below.end());
  }
}

StrongClassifier StrongClassifier::prefix(size_t T) const {
  return StrongClassifier(std::vector<WeightedStump>(stumps_.begin(), stumps_.begin() + std::min(T, stumps_.size())));
}

double StrongClassifier::score(const FeatureVector& a, const FeatureVector& b) const {
  double vote = 0;
  const double* thr = thr_.data();
  const double* alpha = alpha_.data();
  for (const auto& v : votes_) {
    // A feature's difference inline (the thesis's stumps, most of a model); distances by call.
    const size_t k = static_cast<size_t>(v.comparison);
    const double c = v.comparison < kFeatureCount ? std::fabs(a[k] - b[k]) : compare(a, b, v.comparison);
    // +1 stumps vote when c < threshold: all but the first i, i = #thresholds <= c.
    uint32_t i = 0;
    for (uint32_t k = 0; k < v.plus_count; ++k) i += thr[v.plus_begin + k] <= c;
    // −1 stumps vote when c > threshold: the first j, j = #thresholds < c.
    uint32_t j = 0;
    for (uint32_t k = 0; k < v.minus_count; ++k) j += thr[v.minus_begin + k] < c;
    vote += alpha[v.plus_alpha + i] + alpha[v.minus_alpha + j];
  }
  return alpha_total_ > 0 ? vote / alpha_total_ : 0.0;
}

}  // namespace urbanslam::laser_loop
