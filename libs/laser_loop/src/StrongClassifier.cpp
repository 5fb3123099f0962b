#include "urbanslam/laser_loop/StrongClassifier.h"

#include <algorithm>

namespace urbanslam::laser_loop {

StrongClassifier StrongClassifier::prefix(size_t T) const {
  return StrongClassifier(std::vector<WeightedStump>(stumps_.begin(), stumps_.begin() + std::min(T, stumps_.size())));
}

double StrongClassifier::score(const FeatureVector& a, const FeatureVector& b) const {
  double vote = 0, total = 0;
  for (const auto& s : stumps_) {
    total += s.alpha;
    if (s.stump.match(a, b)) vote += s.alpha;
  }
  return total > 0 ? vote / total : 0.0;
}

}  // namespace urbanslam::laser_loop
