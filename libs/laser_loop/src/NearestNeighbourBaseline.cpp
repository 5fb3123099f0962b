#include "urbanslam/laser_loop/NearestNeighbourBaseline.h"

#include <cmath>

namespace urbanslam::laser_loop {

NearestNeighbourBaseline::NearestNeighbourBaseline(const std::vector<FeatureVector>& scans) {
  for (int f = 0; f < kFeatureCount; ++f) {
    double mean = 0, m2 = 0;
    size_t n = 0;
    for (const auto& s : scans) {
      ++n;
      const double d = s[f] - mean;
      mean += d / static_cast<double>(n);
      m2 += d * (s[f] - mean);
    }
    const double sd = n > 1 ? std::sqrt(m2 / static_cast<double>(n - 1)) : 0.0;
    inv_std_[f] = sd > 0 ? 1.0 / sd : 0.0;
  }
}

double NearestNeighbourBaseline::score(const FeatureVector& a, const FeatureVector& b) const {
  double d2 = 0;
  for (int f = 0; f < kFeatureCount; ++f) {
    const double d = (a[f] - b[f]) * inv_std_[f];
    d2 += d * d;
  }
  return -std::sqrt(d2);
}

}  // namespace urbanslam::laser_loop
