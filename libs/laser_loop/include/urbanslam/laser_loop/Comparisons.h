#pragma once
// What a weak classifier looks at for a pair of scans (eq. 3.25's c): one number per comparison.
// Comparison k < kFeatureCount is |f_k(a) − f_k(b)|, the thesis's. The rest compare a whole
// descriptor at once, which single-feature stumps cannot: two range distributions can differ a
// little in every quantile and so pass every stump, while their summed difference tells them
// apart. Measured on a held-out simulated city with a 360° laser (share/laser_loop/README.md).
//  * range_quantile_l1: Σ |q_k(a) − q_k(b)| over the range quantiles (the Wasserstein-1
//    distance between the two clamped range distributions, up to the quantile step);
//  * range_hist_l1: Σ |h_k(a) − h_k(b)| over the range histogram's bins;
//  * range_hist_chi2: Σ (h_k(a) − h_k(b))² / (h_k(a) + h_k(b)) over the bins where the sum > 0.
#include <string>

#include "urbanslam/laser_loop/ScanFeatures.h"

namespace urbanslam::laser_loop {

enum class Distance : int { RangeQuantileL1 = 0, RangeHistogramL1, RangeHistogramChi2 };
constexpr int kDistanceCount = 3;
constexpr int kComparisonCount = kFeatureCount + kDistanceCount;

// The features a distance sums over: [begin, begin + count) of the feature vector.
struct FeatureRange {
  int begin = 0, count = 0;
};
FeatureRange distanceFeatures(Distance d);

double distance(Distance d, const double* a, const double* b);
// Comparison k of the pair (a, b); k in [0, kComparisonCount).
double compare(const FeatureVector& a, const FeatureVector& b, int k);

// Feature names for k < kFeatureCount, then "range_quantile_l1", "range_hist_l1", "range_hist_chi2".
const char* comparisonName(int k);
// Index of a comparison name; -1 when unknown.
int comparisonIndex(const std::string& name);

}  // namespace urbanslam::laser_loop
