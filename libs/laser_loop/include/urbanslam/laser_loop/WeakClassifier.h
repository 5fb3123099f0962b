#pragma once
// Weak classifiers of eq. 3.25: a comparison of two scans (Comparisons.h; the thesis's is
// c_f(a, b) = |f(a) − f(b)|) tested against a threshold. A decision stump with a polarity: +1 says "match" when the features are closer
// than the threshold (the expected case, 3.25's small c_i), −1 when they are farther (learned when it is what the weighted data say).
// Stumps are fitted to minimise the weighted error of eq. 3.28.
#include <cstdint>
#include <vector>

#include "urbanslam/laser_loop/Comparisons.h"

namespace urbanslam::laser_loop {

struct Stump {
  int comparison = 0;  // Comparisons.h: a feature index, or a distance after kFeatureCount
  double threshold = 0;
  int polarity = 1;  // +1: match iff c < threshold; −1: match iff c > threshold
  bool match(double c) const { return polarity > 0 ? c < threshold : c > threshold; }
  bool match(const FeatureVector& a, const FeatureVector& b) const { return match(compare(a, b, comparison)); }
};

// The weak-classifier input of every training pair, comparison-major (c[k][i] = compare(a_i, b_i, k)),
// with labels y_i = 1 for a matching pair and 0 otherwise (eq. 3.26). Only the first
// `comparisons` columns are filled and trained on: kThesisFeatureCount reproduces the thesis.
struct PairTable {
  int comparisons = kComparisonCount;
  std::vector<double> c[kComparisonCount];
  std::vector<uint8_t> y;
  size_t size() const { return y.size(); }
  void add(const FeatureVector& a, const FeatureVector& b, bool match);
};

// The best stump on one comparison for the pairs `order` (the subset, sorted by ascending c[k]) and
// weights w (indexed like the table). Thresholds lie midway between consecutive distinct values,
// or just outside the range. Ties between thresholds keep the first found (polarity +1, lowest
// threshold) so training is deterministic. Returns the stump and its weighted error Σ w_i |c − y|.
struct StumpFit {
  Stump stump;
  double error = 0;
};
StumpFit fitStump(const PairTable& data, int comparison, const std::vector<uint32_t>& order, const std::vector<double>& w);

}  // namespace urbanslam::laser_loop
