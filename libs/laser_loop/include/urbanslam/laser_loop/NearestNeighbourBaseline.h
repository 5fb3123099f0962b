#pragma once
// The learning-free baseline that measures what boosting adds: two scans are alike when their
// feature vectors, each feature scaled to unit standard deviation, are close in Euclidean
// distance (nearest neighbour on the normalised feature vector). The scaling is estimated from the
// scans themselves (no labels), so nothing is learned from matching/non-matching examples.
// Score = −distance, so "higher = more alike" as for the boosted classifier.
#include <vector>

#include "urbanslam/laser_loop/ScanFeatures.h"

namespace urbanslam::laser_loop {

class NearestNeighbourBaseline {
 public:
  // Per-feature standard deviation over `scans` (features with zero spread get weight 0).
  explicit NearestNeighbourBaseline(const std::vector<FeatureVector>& scans);
  double score(const FeatureVector& a, const FeatureVector& b) const;
  const FeatureVector& inverseScale() const { return inv_std_; }

 private:
  FeatureVector inv_std_{};
};

}  // namespace urbanslam::laser_loop
