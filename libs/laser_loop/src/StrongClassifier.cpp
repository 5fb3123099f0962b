#include "urbanslam/laser_loop/StrongClassifier.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::laser_loop {

StrongClassifier::StrongClassifier(std::vector<WeightedStump> stumps) : stumps_(std::move(stumps)) {
  for (const auto& s : stumps_) {
    compiled_.push_back({s.stump.feature, static_cast<double>(s.stump.polarity), s.stump.threshold, s.alpha});
    alpha_total_ += s.alpha;
  }
}

StrongClassifier StrongClassifier::prefix(size_t T) const {
  return StrongClassifier(std::vector<WeightedStump>(stumps_.begin(), stumps_.begin() + std::min(T, stumps_.size())));
}

double StrongClassifier::score(const FeatureVector& a, const FeatureVector& b) const {
  // polarity · (threshold − c) > 0  ⇔  c < threshold (+1) or c > threshold (−1), as Stump::match.
  auto vote_of = [&](const Compiled& s) {
    const double c = std::fabs(a[s.feature] - b[s.feature]);
    return (s.signed_threshold_sign * (s.threshold - c) > 0) ? s.alpha : 0.0;
  };
  // Four independent sums so the additions do not wait on each other (the sum of 50 votes is
  // otherwise one long latency chain).
  double v0 = 0, v1 = 0, v2 = 0, v3 = 0;
  const size_t n = compiled_.size();
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    v0 += vote_of(compiled_[i]);
    v1 += vote_of(compiled_[i + 1]);
    v2 += vote_of(compiled_[i + 2]);
    v3 += vote_of(compiled_[i + 3]);
  }
  for (; i < n; ++i) v0 += vote_of(compiled_[i]);
  return alpha_total_ > 0 ? ((v0 + v1) + (v2 + v3)) / alpha_total_ : 0.0;
}

}  // namespace urbanslam::laser_loop
