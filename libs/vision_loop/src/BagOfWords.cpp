#include "urbanslam/vision_loop/BagOfWords.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::vision_loop {

BagOfWords makeBagOfWords(std::vector<WordWeight> raw) {
  std::sort(raw.begin(), raw.end(), [](const WordWeight& a, const WordWeight& b) { return a.word < b.word; });
  BagOfWords bag;
  double total = 0;
  for (const auto& e : raw) {
    if (!(e.weight > 0)) continue;
    if (!bag.entries.empty() && bag.entries.back().word == e.word)
      bag.entries.back().weight += e.weight;
    else
      bag.entries.push_back(e);
    total += e.weight;
  }
  if (total > 0)
    for (auto& e : bag.entries) e.weight = static_cast<float>(e.weight / total);
  return bag;
}

float l1Score(const BagOfWords& a, const BagOfWords& b) {
  // Full ‖a − b‖₁ over the union of words (words in only one bag count too): the brute-force
  // definition, which the inverted-file score must reproduce.
  double l1 = 0;
  size_t i = 0, j = 0;
  while (i < a.entries.size() || j < b.entries.size()) {
    if (j == b.entries.size() || (i < a.entries.size() && a.entries[i].word < b.entries[j].word)) {
      l1 += a.entries[i++].weight;
    } else if (i == a.entries.size() || b.entries[j].word < a.entries[i].word) {
      l1 += b.entries[j++].weight;
    } else {
      l1 += std::fabs(a.entries[i++].weight - b.entries[j++].weight);
    }
  }
  if (a.empty() || b.empty()) return 0.f;
  return static_cast<float>(std::clamp(1.0 - 0.5 * l1, 0.0, 1.0));
}

}  // namespace urbanslam::vision_loop
