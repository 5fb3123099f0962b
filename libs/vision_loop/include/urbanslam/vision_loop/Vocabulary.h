#pragma once
// The vocabulary tree (Nistér & Stewénius 2006; thesis §4.2.2–4.2.3): a read-only hierarchy of
// cluster centres trained offline on images unrelated to the run. A descriptor descends from the
// root, choosing at each level the child whose centre is nearest (smallest angle for SIFT,
// smallest Hamming distance for ORB): at most k·L comparisons for k branches and L levels.
// The leaves are the words; each word carries an IDF weight w_i = ln(N / N_i) from the N
// training images, N_i of which contain it.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "urbanslam/vision_loop/BagOfWords.h"
#include "urbanslam/vision_loop/Descriptor.h"

namespace urbanslam::vision_loop {

// The raw arrays of a tree, nodes in breadth-first order so that the children of a node are
// contiguous (one cache-friendly scan per level) and the whole tree saves/loads as a few flat
// arrays. Node 0 is the root (its centre is unused).
struct VocabularyData {
  DescriptorType type = DescriptorType::Sift;
  uint32_t branching = 0;        // k
  uint32_t depth = 0;            // L (leaves may sit higher where data ran out)
  uint64_t training_images = 0;  // N of the IDF weights
  uint64_t training_descriptors = 0;
  std::vector<uint32_t> first_child;   // per node; children are [first_child, first_child + child_count)
  std::vector<uint32_t> child_count;   // per node; 0 for a leaf
  std::vector<uint32_t> word_of_node;  // per node; kNoWord for an inner node
  std::vector<uint8_t> centres;        // node_count × descriptorBytes(type)
  std::vector<float> inverse_norms;    // per node, 1/|centre| (SIFT only; empty for ORB)
  std::vector<uint32_t> node_of_word;  // per word
  std::vector<float> idf;              // per word

  static constexpr uint32_t kNoWord = 0xffffffffu;
  size_t nodeCount() const { return first_child.size(); }
  size_t wordCount() const { return node_of_word.size(); }
  // Throws common::InputError when the arrays are inconsistent (sizes, child ranges, words).
  void validate() const;
};

class Vocabulary {
 public:
  Vocabulary() = default;
  // Validates the arrays (throws common::InputError when inconsistent).
  explicit Vocabulary(VocabularyData data);

  DescriptorType descriptorType() const { return data_.type; }
  int descriptorBytes() const { return bytes_; }
  uint32_t branching() const { return data_.branching; }
  uint32_t depth() const { return data_.depth; }
  size_t wordCount() const { return data_.wordCount(); }
  size_t nodeCount() const { return data_.nodeCount(); }
  bool empty() const { return data_.wordCount() == 0; }
  float idf(WordId w) const { return data_.idf[w]; }
  const uint8_t* centre(uint32_t node) const { return data_.centres.data() + size_t(node) * bytes_; }
  const VocabularyData& data() const { return data_; }

  // The word of one descriptor (`bytes` = descriptorBytes()); ≤ k·L comparisons.
  WordId quantize(const uint8_t* descriptor) const;
  // Bag of words of an image: tf-idf weights (count · idf), L1-normalised. `descriptors` is
  // CV_8U with descriptorBytes() columns. Optionally returns the word of every row.
  BagOfWords transform(const cv::Mat& descriptors, std::vector<WordId>* words = nullptr) const;

  // One-line description, e.g. "sift k=10 L=4: 10000 words from 412 images (201 133 descriptors)".
  std::string summary() const;

 private:
  VocabularyData data_;
  int bytes_ = 0;
};

}  // namespace urbanslam::vision_loop
