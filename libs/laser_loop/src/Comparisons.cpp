#include "urbanslam/laser_loop/Comparisons.h"

#include <cmath>

namespace urbanslam::laser_loop {

namespace {
constexpr const char* kDistanceNames[kDistanceCount] = {"range_quantile_l1", "range_hist_l1", "range_hist_chi2"};
}

FeatureRange distanceFeatures(Distance d) {
  if (d == Distance::RangeQuantileL1) return {kThesisFeatureCount + kShapeQuantiles, kRangeQuantiles};
  return {kThesisFeatureCount + kShapeHistogram, kHistogramBins};
}

double distance(Distance d, const double* a, const double* b) {
  const FeatureRange r = distanceFeatures(d);
  double sum = 0;
  for (int i = r.begin; i < r.begin + r.count; ++i) {
    const double diff = a[i] - b[i];
    if (d == Distance::RangeHistogramChi2) {
      const double both = a[i] + b[i];
      if (both > 0) sum += diff * diff / both;
    } else {
      sum += std::fabs(diff);
    }
  }
  return sum;
}

double compare(const FeatureVector& a, const FeatureVector& b, int k) {
  if (k < kFeatureCount) return std::fabs(a[static_cast<size_t>(k)] - b[static_cast<size_t>(k)]);
  return distance(static_cast<Distance>(k - kFeatureCount), a.data(), b.data());
}

const char* comparisonName(int k) {
  if (k >= 0 && k < kFeatureCount) return featureName(k);
  return k >= kFeatureCount && k < kComparisonCount ? kDistanceNames[k - kFeatureCount] : "?";
}

int comparisonIndex(const std::string& name) {
  for (int k = 0; k < kComparisonCount; ++k)
    if (name == comparisonName(k)) return k;
  return -1;
}

}  // namespace urbanslam::laser_loop
