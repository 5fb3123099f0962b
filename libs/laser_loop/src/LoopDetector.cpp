#include "urbanslam/laser_loop/LoopDetector.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::laser_loop {

LoopDetector::LoopDetector(ClassifierModel model) : model_(std::move(model)), factor_(model_.factor) {
  std::vector<int> column(kFeatureCount, -1);
  for (const auto& s : model_.classifier.stumps()) {
    int& c = column[s.stump.feature];
    if (c < 0) {
      c = static_cast<int>(used_features_.size());
      used_features_.push_back(s.stump.feature);
    }
    stumps_.push_back({c, static_cast<float>(s.stump.threshold), static_cast<float>(s.alpha), s.stump.polarity});
    alpha_total_ += s.alpha;
  }
  columns_.resize(used_features_.size());
}

LoopDetector LoopDetector::fromFile(const std::string& path) { return LoopDetector(loadModel(path)); }

void LoopDetector::reserve(size_t n) {
  keyframes_.reserve(n);
  for (auto& c : columns_) c.reserve(n);
}

size_t LoopDetector::addKeyframe(const FeatureVector& f) {
  keyframes_.push_back(f);
  for (size_t c = 0; c < columns_.size(); ++c) columns_[c].push_back(static_cast<float>(f[used_features_[c]]));
  return keyframes_.size() - 1;
}

double LoopDetector::score(const FeatureVector& q, size_t id) const {
  return model_.classifier.score(q, keyframes_.at(id));
}

std::vector<LoopDetector::Match> LoopDetector::query(const FeatureVector& q, const std::vector<size_t>& candidates) const {
  std::vector<Match> out;
  for (size_t id : candidates) {
    const double s = score(q, id);
    if (s >= factor_) out.push_back({id, s});
  }
  std::stable_sort(out.begin(), out.end(), [](const Match& a, const Match& b) { return a.score > b.score; });
  return out;
}

void LoopDetector::screen(const FeatureVector& query, std::vector<float>& scores) const {
  const size_t n = keyframes_.size();
  scores.resize(n);
  if (n == 0) return;
  // Blocks small enough that the accumulator and the column slices stay in L1 while every stump
  // passes over them; the inner loops are branch-free so the compiler vectorises them.
  constexpr size_t kBlock = 512;
  alignas(64) float acc[kBlock];
  const float inv_total = alpha_total_ > 0 ? static_cast<float>(1.0 / alpha_total_) : 0.f;
  std::vector<float> q(used_features_.size());
  for (size_t c = 0; c < q.size(); ++c) q[c] = static_cast<float>(query[used_features_[c]]);
  for (size_t base = 0; base < n; base += kBlock) {
    const size_t m = std::min(kBlock, n - base);
    std::fill(acc, acc + kBlock, 0.f);
    for (const auto& st : stumps_) {
      const float* v = columns_[static_cast<size_t>(st.column)].data() + base;
      const float qv = q[static_cast<size_t>(st.column)], thr = st.threshold, a = st.alpha;
      if (st.polarity > 0) {
        for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) < thr ? a : 0.f;
      } else {
        for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) > thr ? a : 0.f;
      }
    }
    for (size_t i = 0; i < m; ++i) scores[base + i] = acc[i] * inv_total;
  }
}

std::vector<LoopDetector::Match> LoopDetector::queryAll(const FeatureVector& q) const {
  std::vector<float> s;
  screen(q, s);
  std::vector<Match> out;
  const float f = static_cast<float>(factor_);
  for (size_t i = 0; i < s.size(); ++i)
    if (s[i] >= f) out.push_back({i, s[i]});
  std::stable_sort(out.begin(), out.end(), [](const Match& a, const Match& b) { return a.score > b.score; });
  return out;
}

}  // namespace urbanslam::laser_loop
