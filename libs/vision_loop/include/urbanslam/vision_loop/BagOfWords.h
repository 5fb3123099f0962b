#pragma once
// An image as a sparse vector of visual words with tf-idf weights, L1-normalised (Nistér &
// Stewénius 2006 found L1 better than L2 for retrieval).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace urbanslam::vision_loop {

using WordId = uint32_t;

struct WordWeight {
  WordId word;
  float weight;
};

struct BagOfWords {
  std::vector<WordWeight> entries;  // sorted by word, weights > 0 summing to 1 (or empty)
  size_t size() const { return entries.size(); }
  bool empty() const { return entries.empty(); }
};

// Builds a normalised bag from per-word raw weights (word, weight) in any order, summing
// duplicates; words of weight 0 are dropped. Used by Vocabulary::transform and the tests.
BagOfWords makeBagOfWords(std::vector<WordWeight> raw);

// Similarity of two bags: 1 − ½·‖a − b‖₁ ∈ [0, 1] (1: same distribution of words, 0: no word in
// common). Computed by merging the two sparse vectors; the database computes the same value
// through its inverted files. Symmetric.
float l1Score(const BagOfWords& a, const BagOfWords& b);

}  // namespace urbanslam::vision_loop
