#include "urbanslam/laser_loop/LoopDetector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "urbanslam/common/Error.h"

namespace urbanslam::laser_loop {

LoopDetector::LoopDetector(ClassifierModel model) : model_(std::move(model)), factor_(model_.factor) {
  // features(scan) computes each scan alone; a submap model would silently get other features.
  if (model_.submap_window_m > 0)
    throw common::InputError("laser loop model uses submap_window_m " + std::to_string(model_.submap_window_m) +
                             " (virtual 360° scans), which the detector does not build; use a model trained "
                             "without --submap-window");
  std::vector<int> column(kFeatureCount, -1);
  auto useFeature = [&](int f) {
    int& c = column[static_cast<size_t>(f)];
    if (c < 0) {
      c = static_cast<int>(used_features_.size());
      used_features_.push_back(f);
    }
    return c;
  };
  std::vector<int> slot(kDistanceCount, -1);
  for (const auto& s : model_.classifier.stumps()) {
    const int k = s.stump.comparison;
    CompiledStump cs{0, -1, static_cast<float>(s.stump.threshold), static_cast<float>(s.alpha), s.stump.polarity};
    if (k < kFeatureCount) {
      cs.column = useFeature(k);
    } else {
      int& d = slot[static_cast<size_t>(k - kFeatureCount)];
      if (d < 0) {
        d = static_cast<int>(distances_.size());
        const FeatureRange r = distanceFeatures(static_cast<Distance>(k - kFeatureCount));
        UsedDistance u{static_cast<Distance>(k - kFeatureCount), {}};
        for (int f = r.begin; f < r.begin + r.count; ++f) u.columns.push_back(useFeature(f));
        distances_.push_back(std::move(u));
      }
      cs.distance = d;
    }
    stumps_.push_back(cs);
    alpha_total_ += s.alpha;
  }
  columns_.resize(used_features_.size());
}

LoopDetector LoopDetector::fromFile(const std::string& path) { return LoopDetector(loadModel(path)); }

void LoopDetector::reserve(size_t n) {
  for (auto& c : columns_) c.reserve(n);
}

size_t LoopDetector::addKeyframe(const FeatureVector& f) {
  for (size_t c = 0; c < columns_.size(); ++c) {
    const double v = f[static_cast<size_t>(used_features_[c])];
    // Grown by an eighth, not doubled: a column of a million keyframes would leave up to half
    // its capacity unused. The screening reads each column as one array, so no blocks.
    if (columns_[c].size() == columns_[c].capacity()) columns_[c].reserve(columns_[c].size() + columns_[c].size() / 8 + 1024);
    columns_[c].push_back(static_cast<float>(v));
  }
  return count_++;
}

void LoopDetector::fillUsed(size_t id, FeatureVector& f) const {
  if (id >= count_) throw std::out_of_range("LoopDetector: no keyframe " + std::to_string(id));
  for (size_t c = 0; c < used_features_.size(); ++c) f[static_cast<size_t>(used_features_[c])] = columns_[c][id];
}

FeatureVector LoopDetector::keyframe(size_t id) const {
  FeatureVector f{};
  fillUsed(id, f);
  return f;
}

// The classifier reads only the features its stumps and distances use, which are the ones
// stored: a scratch vector needs only those written, whatever the rest holds.
double LoopDetector::score(const FeatureVector& q, size_t id) const {
  thread_local FeatureVector f{};
  fillUsed(id, f);
  return model_.classifier.score(q, f);
}

double LoopDetector::score(size_t query_id, size_t id) const {
  thread_local FeatureVector q{}, f{};
  fillUsed(query_id, q);
  fillUsed(id, f);
  return model_.classifier.score(q, f);
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

namespace {

// A stump as the screen evaluates it on a block of keyframes.
struct BlockStump {
  const float* column;  // the block's values: a feature column from the block's first keyframe, or a distance buffer
  float query, threshold, alpha;
  int polarity;
};

constexpr size_t kBlock = 512;

// A distance between the query's and each of a block's m keyframes' descriptors (Comparisons.h),
// in single precision: the stumps on it then read it as a column with query 0.
__attribute__((target_clones("avx2", "default"))) void distanceBlock(Distance d, const float* const* columns, const float* query,
                                                                     size_t count, size_t base, size_t m, float* out) {
  for (size_t i = 0; i < m; ++i) out[i] = 0.f;
  for (size_t k = 0; k < count; ++k) {
    const float* v = columns[k] + base;
    const float q = query[k];
    if (d == Distance::RangeHistogramChi2) {
      // Histogram fractions are >= 0, so where both are 0 the difference is 0 too: a floor on
      // the divisor instead of a test keeps the loop branch-free (and vectorised).
      for (size_t i = 0; i < m; ++i) {
        const float diff = q - v[i];
        out[i] += diff * diff / std::max(q + v[i], 1e-30f);
      }
    } else {
      for (size_t i = 0; i < m; ++i) out[i] += std::fabs(q - v[i]);
    }
  }
}

// One block of keyframes against every stump. Built for AVX2 and for the baseline ISA; the
// loader picks the variant the CPU supports (GCC function multi-versioning), so the binary stays
// portable while an AVX2 machine screens 8 keyframes per instruction.
__attribute__((target_clones("avx2", "default"))) void screenBlock(const BlockStump* stumps, size_t n_stumps, size_t m, float inv_total,
                                                                   float* out) {
  alignas(64) float acc[kBlock];
  for (size_t i = 0; i < kBlock; ++i) acc[i] = 0.f;
  for (size_t k = 0; k < n_stumps; ++k) {
    const BlockStump& st = stumps[k];
    const float* v = st.column;
    const float qv = st.query, thr = st.threshold, a = st.alpha;
    if (st.polarity > 0) {
      for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) < thr ? a : 0.f;
    } else {
      for (size_t i = 0; i < m; ++i) acc[i] += std::fabs(qv - v[i]) > thr ? a : 0.f;
    }
  }
  for (size_t i = 0; i < m; ++i) out[i] = acc[i] * inv_total;
}

}  // namespace

void LoopDetector::screen(const FeatureVector& query, std::vector<float>& scores) const {
  const size_t n = count_;
  scores.resize(n);
  if (n == 0) return;
  // Blocks small enough that the accumulator, the distances and the column slices stay in L1
  // while every stump passes over them; the inner loops are branch-free so the compiler
  // vectorises them.
  const float inv_total = alpha_total_ > 0 ? static_cast<float>(1.0 / alpha_total_) : 0.f;
  std::vector<std::vector<const float*>> dist_columns(distances_.size());
  std::vector<std::vector<float>> dist_query(distances_.size());
  for (size_t d = 0; d < distances_.size(); ++d)
    for (int c : distances_[d].columns) {
      dist_columns[d].push_back(columns_[static_cast<size_t>(c)].data());
      dist_query[d].push_back(static_cast<float>(query[static_cast<size_t>(used_features_[static_cast<size_t>(c)])]));
    }
  std::vector<std::array<float, kBlock>> dist(distances_.size());
  std::vector<BlockStump> bs(stumps_.size());
  for (size_t k = 0; k < stumps_.size(); ++k) {
    const auto& st = stumps_[k];
    const float q = st.distance >= 0 ? 0.f : static_cast<float>(query[static_cast<size_t>(used_features_[static_cast<size_t>(st.column)])]);
    bs[k] = {nullptr, q, st.threshold, st.alpha, st.polarity};
  }
  for (size_t base = 0; base < n; base += kBlock) {
    const size_t m = std::min(kBlock, n - base);
    for (size_t d = 0; d < distances_.size(); ++d)
      distanceBlock(distances_[d].distance, dist_columns[d].data(), dist_query[d].data(), dist_columns[d].size(), base, m, dist[d].data());
    for (size_t k = 0; k < stumps_.size(); ++k) {
      const auto& st = stumps_[k];
      bs[k].column =
          st.distance >= 0 ? dist[static_cast<size_t>(st.distance)].data() : columns_[static_cast<size_t>(st.column)].data() + base;
    }
    screenBlock(bs.data(), bs.size(), m, inv_total, scores.data() + base);
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
