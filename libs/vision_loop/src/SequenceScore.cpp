#include "urbanslam/vision_loop/SequenceScore.h"

#include <algorithm>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

SequenceScore::SequenceScore(int frames) : frames_(frames) {
  if (frames < 1) throw common::InputError("sequence score: the window needs at least one frame");
}

float SequenceScore::score(ImageId image, float eta_now) const {
  float sum = eta_now;
  const long j = static_cast<long>(image);
  for (size_t k = 1; k < static_cast<size_t>(frames_) && k <= history_.size(); ++k) {
    const long lo = j - 2 * static_cast<long>(k), hi = j - std::max(1L, static_cast<long>(k) / 2);
    if (hi < 0) break;
    const auto& results = history_[k - 1];
    auto it =
        std::lower_bound(results.begin(), results.end(), lo, [](const ScoredImage& s, long v) { return static_cast<long>(s.image) < v; });
    float best = 0;
    for (; it != results.end() && static_cast<long>(it->image) <= hi; ++it) best = std::max(best, it->eta);
    sum += best;
  }
  return sum / static_cast<float>(frames_);
}

void SequenceScore::push(std::vector<ScoredImage> results) {
  if (frames_ < 2) return;
  std::sort(results.begin(), results.end(), [](const ScoredImage& a, const ScoredImage& b) { return a.image < b.image; });
  history_.push_front(std::move(results));
  if (history_.size() > static_cast<size_t>(frames_ - 1)) history_.pop_back();
}

}  // namespace urbanslam::vision_loop
