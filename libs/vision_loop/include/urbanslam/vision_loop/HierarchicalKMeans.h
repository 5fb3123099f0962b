#pragma once
// Hierarchical k-means (thesis §4.2.2, Appendix A; Nistér & Stewénius 2006): the root clusters
// all training descriptors into k groups, each group is clustered again into k, down to depth L.
// k-means++ seeding (Arthur & Vassilvitskii 2007) avoids the bad local minima of random seeds,
// which matter here because a poor split near the root is inherited by 10^5 words below it.
// SIFT uses spherical k-means (angles, matching the §4.2.3 classification); ORB uses Hamming
// distance with bitwise-majority centres (as DBoW2), since a mean of bit strings is not binary.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "urbanslam/vision_loop/Descriptor.h"
#include "urbanslam/vision_loop/Vocabulary.h"

namespace urbanslam::vision_loop {

// Descriptors stored row after row (count × bytes), not owned.
struct DescriptorSet {
  const uint8_t* data = nullptr;
  size_t count = 0;
  int bytes = 0;
  const uint8_t* row(size_t i) const { return data + i * size_t(bytes); }
};

struct KMeansOptions {
  uint32_t branching = 10;  // k
  uint32_t depth = 6;       // L: up to k^L words
  int max_iterations = 10;  // Lloyd iterations per node (stops earlier when assignments settle)
  uint64_t seed = 1;        // same seed + same data → same tree, whatever the thread count
  int threads = 0;          // 0: all hardware threads
};

struct KMeansResult {
  std::vector<uint8_t> centres;      // clusters × bytes (empty clusters removed)
  std::vector<uint32_t> assignment;  // per input point: its cluster, w.r.t. the final centres
  int iterations = 0;
  size_t clusters() const { return assignment.empty() ? 0 : centres.size() / bytes_; }
  size_t bytes_ = 1;
};

// One level of k-means over `points` (indices into `set`). Returns at most k clusters; fewer
// when there are fewer distinct points. Centres for SIFT are unit directions scaled to SIFT's
// own norm (512) and rounded to bytes, so they are compared exactly as at run time.
KMeansResult kmeans(const DescriptorSet& set, const std::vector<uint32_t>& points, DescriptorType type, uint32_t k, int max_iterations,
                    uint64_t seed, int threads = 1);

// progress(fraction in [0,1], status)
using ProgressFn = std::function<void(double, const std::string&)>;

// The whole tree. The result has words and an all-zero IDF; trainVocabulary() fills the IDF.
VocabularyData buildVocabularyTree(const DescriptorSet& set, DescriptorType type, const KMeansOptions& options,
                                   const ProgressFn& progress = {});

// 1/|c| of a byte centre (0 for the zero vector).
float inverseNorm(const uint8_t* centre, int bytes);

}  // namespace urbanslam::vision_loop
