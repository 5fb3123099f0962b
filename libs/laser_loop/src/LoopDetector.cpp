#include "urbanslam/laser_loop/LoopDetector.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/common/Error.h"

namespace urbanslam::laser_loop {

LoopDetector::LoopDetector(ClassifierModel model) : model_(std::move(model)), factor_(model_.factor) {
  // features(scan) computes each scan alone; a submap model would silently get other features.
  if (model_.submap_window_m > 0)
    throw common::InputError("laser loop model uses submap_window_m " + std::to_string(model_.submap_window_m) +
                             " (virtual 360° scans), which the detector does not build; use a model trained "
                             "without --submap-window");
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

double LoopDetector::score(const FeatureVector& q, size_t id) const { return model_.classifier.score(q, keyframes_.at(id)); }

std::vector<LoopDetector::Match> LoopDetector::query(const FeatureVector& q, const std::vector<size_t>& candidates) const {
  std::vector<Match> out;
  for (size_t id : candidates) {
    const double s = score(q, id);
    if (s >= factor_) out.push_back({id, s});
  }
  std::stable_sort(out.begin(), out.end(), [](const Match& a, const Match& b) { return a.score > b.score; });
  return out;
}

namespace {

// One block of keyframes against every stump. Built for AVX2 and for the baseline ISA; the
// loader picks the variant the CPU supports (GCC function multi-versioning), so the binary stays
// portable while an AVX2 machine screens 8 keyframes per instruction.
struct BlockStump {
  const float* column;
  float query, threshold, alpha;
  int polarity;
};

__attribute__((target_clones("avx2", "default"))) void screenBlock(const BlockStump* stumps, size_t n_stumps, size_t base, size_t m,
                                                                   float inv_total, float* out) {
  constexpr size_t kBlock = 512;
  alignas(64) float acc[kBlock];
  for (size_t i = 0; i < kBlock; ++i) acc[i] = 0.f;
  for (size_t k = 0; k < n_stumps; ++k) {
    const BlockStump& st = stumps[k];
    const float* v = st.column + base;
    const float qv = st.query, thr = st.threshold, a = st.alpha;
    if (st.polarity > 0) {
      for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) < thr ? a : 0.f;
    } else {
      for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) > thr ? a : 0.f;
    }
  }
  for (size_t i = 0; i < m; ++i) out[base + i] = acc[i] * inv_total;
}

}  // namespace

void LoopDetector::screen(const FeatureVector& query, std::vector<float>& scores) const {
  const size_t n = keyframes_.size();
  scores.resize(n);
  if (n == 0) return;
  // Blocks small enough that the accumulator and the column slices stay in L1 while every stump
  // passes over them; the inner loops are branch-free so the compiler vectorises them.
  constexpr size_t kBlock = 512;
  const float inv_total = alpha_total_ > 0 ? static_cast<float>(1.0 / alpha_total_) : 0.f;
  std::vector<BlockStump> bs;
  bs.reserve(stumps_.size());
  for (const auto& st : stumps_)
    bs.push_back({columns_[static_cast<size_t>(st.column)].data(),
                  static_cast<float>(query[used_features_[static_cast<size_t>(st.column)]]), st.threshold, st.alpha, st.polarity});
  for (size_t base = 0; base < n; base += kBlock)
    screenBlock(bs.data(), bs.size(), base, std::min(kBlock, n - base), inv_total, scores.data());
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
