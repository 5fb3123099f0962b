#include "urbanslam/vision_loop/Vocabulary.h"

#include <cmath>
#include <sstream>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

void VocabularyData::validate() const {
  auto bad = [](const std::string& why) { throw common::InputError("vocabulary: " + why); };
  if (type != DescriptorType::Sift && type != DescriptorType::Orb) bad("unknown descriptor type");
  const size_t n = nodeCount();
  const size_t bytes = static_cast<size_t>(descriptorBytes(type));
  if (n == 0) bad("no nodes");
  if (child_count.size() != n || word_of_node.size() != n) bad("per-node arrays differ in length");
  if (centres.size() != n * bytes) bad("centre array has the wrong length");
  if (type == DescriptorType::Sift && inverse_norms.size() != n) bad("inverse norms missing");
  if (idf.size() != node_of_word.size()) bad("IDF and word arrays differ in length");
  for (size_t i = 0; i < n; ++i) {
    if (child_count[i] == 0) {
      if (word_of_node[i] >= node_of_word.size() || node_of_word[word_of_node[i]] != i)
        bad("leaf " + std::to_string(i) + " has no valid word");
    } else {
      // Breadth-first order: children come after their parent, within the array.
      if (first_child[i] <= i || uint64_t(first_child[i]) + child_count[i] > n)
        bad("node " + std::to_string(i) + " has an invalid child range");
      if (word_of_node[i] != kNoWord) bad("inner node " + std::to_string(i) + " has a word");
    }
  }
  for (size_t w = 0; w < node_of_word.size(); ++w)
    if (node_of_word[w] >= n || word_of_node[node_of_word[w]] != w) bad("word " + std::to_string(w) + " has no leaf");
}

Vocabulary::Vocabulary(VocabularyData data) : data_(std::move(data)) {
  data_.validate();
  bytes_ = vision_loop::descriptorBytes(data_.type);
}

WordId Vocabulary::quantize(const uint8_t* d) const {
  uint32_t node = 0;
  const uint32_t* first = data_.first_child.data();
  const uint32_t* count = data_.child_count.data();
  if (data_.type == DescriptorType::Sift) {
    const float* inv = data_.inverse_norms.data();
    while (count[node] != 0) {
      const uint32_t c0 = first[node], c1 = c0 + count[node];
      uint32_t best = c0;
      float best_cos = -1.f;
      for (uint32_t c = c0; c < c1; ++c) {
        // cos(angle) up to the common factor 1/|d|.
        const float cos = static_cast<float>(dotProduct(d, centre(c), bytes_)) * inv[c];
        if (cos > best_cos) best_cos = cos, best = c;
      }
      node = best;
    }
  } else {
    while (count[node] != 0) {
      const uint32_t c0 = first[node], c1 = c0 + count[node];
      uint32_t best = c0;
      int best_d = 1 << 30;
      for (uint32_t c = c0; c < c1; ++c) {
        const int dist = hammingDistance(d, centre(c), bytes_);
        if (dist < best_d) best_d = dist, best = c;
      }
      node = best;
    }
  }
  return data_.word_of_node[node];
}

BagOfWords Vocabulary::transform(const cv::Mat& descriptors, std::vector<WordId>* words) const {
  if (words) words->clear();
  if (descriptors.empty()) return {};
  if (descriptors.type() != CV_8U || descriptors.cols != bytes_)
    throw common::InputError("vocabulary (" + descriptorName(data_.type) + ", " + std::to_string(bytes_) +
                             " bytes) cannot quantize descriptors of " + std::to_string(descriptors.cols) + " columns / type " +
                             std::to_string(descriptors.type()));
  std::vector<WordWeight> raw;
  raw.reserve(descriptors.rows);
  for (int r = 0; r < descriptors.rows; ++r) {
    const WordId w = quantize(descriptors.ptr<uint8_t>(r));
    if (words) words->push_back(w);
    // tf·idf: each occurrence adds idf; the 1/n_d of tf cancels in the L1 normalisation.
    raw.push_back({w, data_.idf[w]});
  }
  return makeBagOfWords(std::move(raw));
}

std::string Vocabulary::summary() const {
  std::ostringstream s;
  s << descriptorName(data_.type) << " k=" << data_.branching << " L=" << data_.depth << ": " << wordCount() << " words, " << nodeCount()
    << " nodes, from " << data_.training_images << " images (" << data_.training_descriptors << " descriptors)";
  return s.str();
}

}  // namespace urbanslam::vision_loop
