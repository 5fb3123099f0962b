#pragma once
// The run-time image database (thesis §4.2.4–4.2.5): every added image's bag of words goes into
// inverted files (word → images containing it, with the word's weight there). A query touches
// only the inverted files of its own words, so its cost grows with the lengths of those lists,
// not with the number of images.
//
// Score: Nistér & Stewénius' L1 distance of normalised vectors, as the similarity
// s(q, d) = 1 − ½‖q − d‖₁ ∈ [0, 1]. For non-negative, L1-normalised q and d,
// ‖q − d‖₁ = 2 − Σ_{i: q_i>0, d_i>0} (q_i + d_i − |q_i − d_i|) = 2 − 2 Σ_i min(q_i, d_i),
// so s(q, d) = Σ_i min(q_i, d_i) summed over the words the two share: exactly the inverted-file
// traversal.
#include <cstdint>
#include <vector>

#include "urbanslam/vision_loop/BagOfWords.h"

namespace urbanslam::vision_loop {

using ImageId = uint32_t;

struct QueryResult {
  ImageId image;
  float score;  // 1 − ½‖q − d‖₁
};

struct QueryOptions {
  size_t max_results = 10;                           // top-k by score
  ImageId max_image = 0xffffffffu;                   // only images with id < max_image (e.g. not the last few frames)
  const std::vector<ImageId>* candidates = nullptr;  // when set: only these images (from the pose filter)
  float min_score = 0.f;                             // results below are dropped
};

class ImageDatabase {
 public:
  // `word_count`: the vocabulary's word count (word ids are < word_count).
  explicit ImageDatabase(size_t word_count);

  // Adds an image; ids are consecutive from 0 in the order of addition.
  ImageId add(const BagOfWords& bag);
  size_t size() const { return images_; }
  size_t wordCount() const { return inverted_.size(); }
  // Total postings over all inverted files (memory: 8 bytes each).
  size_t postingCount() const { return postings_; }
  // Images containing word w.
  size_t invertedFileLength(WordId w) const { return inverted_[w].size(); }

  // Top-k images by score, best first (ties: lower id first). Not thread-safe (scratch buffers).
  std::vector<QueryResult> query(const BagOfWords& bag, const QueryOptions& options = {}) const;

  // Score of `bag` against every image (brute force over the inverted files; for tests/eval).
  std::vector<float> scoreAll(const BagOfWords& bag) const;

 private:
  struct Posting {
    ImageId image;
    float weight;
  };
  std::vector<std::vector<Posting>> inverted_;
  size_t images_ = 0, postings_ = 0;
  // Query scratch: dense accumulator + list of touched images, reset after each query so a query
  // costs O(postings visited), not O(images).
  mutable std::vector<float> accumulator_;
  mutable std::vector<ImageId> touched_;
  mutable std::vector<uint8_t> allowed_;
};

}  // namespace urbanslam::vision_loop
