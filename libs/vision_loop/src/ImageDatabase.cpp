#include "urbanslam/vision_loop/ImageDatabase.h"

#include <algorithm>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

ImageDatabase::ImageDatabase(size_t word_count) : inverted_(word_count) {}

ImageId ImageDatabase::add(const BagOfWords& bag) {
  const ImageId id = static_cast<ImageId>(images_);
  for (const auto& e : bag.entries) {
    if (e.word >= inverted_.size())
      throw common::InputError("bag of words has word " + std::to_string(e.word) + " beyond the vocabulary (" +
                               std::to_string(inverted_.size()) + " words)");
    inverted_[e.word].push_back({id, e.weight});
  }
  postings_ += bag.entries.size();
  ++images_;
  accumulator_.resize(images_, 0.f);
  return id;
}

std::vector<QueryResult> ImageDatabase::query(const BagOfWords& bag, const QueryOptions& options) const {
  const ImageId limit = static_cast<ImageId>(std::min<size_t>(options.max_image, images_));
  const bool restricted = options.candidates != nullptr;
  if (restricted) {
    allowed_.resize(images_, 0);
    for (ImageId c : *options.candidates)
      if (c < limit) allowed_[c] = 1;
  }
  touched_.clear();
  for (const auto& e : bag.entries) {
    if (e.word >= inverted_.size()) continue;
    const float q = e.weight;
    // Postings are in increasing image order: stop at the first one past the limit.
    for (const Posting& p : inverted_[e.word]) {
      if (p.image >= limit) break;
      if (restricted && !allowed_[p.image]) continue;
      float& acc = accumulator_[p.image];
      if (acc == 0.f) touched_.push_back(p.image);
      acc += std::min(q, p.weight);
    }
  }
  std::vector<QueryResult> results;
  results.reserve(touched_.size());
  for (ImageId i : touched_) {
    const float s = std::min(1.f, accumulator_[i]);
    accumulator_[i] = 0.f;
    if (s >= options.min_score) results.push_back({i, s});
  }
  if (restricted)
    for (ImageId c : *options.candidates)
      if (c < allowed_.size()) allowed_[c] = 0;
  auto better = [](const QueryResult& a, const QueryResult& b) { return a.score > b.score || (a.score == b.score && a.image < b.image); };
  if (results.size() > options.max_results) {
    std::nth_element(results.begin(), results.begin() + options.max_results, results.end(), better);
    results.resize(options.max_results);
  }
  std::sort(results.begin(), results.end(), better);
  return results;
}

std::vector<float> ImageDatabase::scoreAll(const BagOfWords& bag) const {
  std::vector<float> s(images_, 0.f);
  for (const auto& e : bag.entries) {
    if (e.word >= inverted_.size()) continue;
    for (const Posting& p : inverted_[e.word]) s[p.image] += std::min(e.weight, p.weight);
  }
  for (float& v : s) v = std::min(1.f, v);
  return s;
}

}  // namespace urbanslam::vision_loop
