#include "urbanslam/vision_loop/HierarchicalKMeans.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {
namespace {

constexpr double kSiftNorm = 512.0;  // OpenCV's SIFT_INT_DESCR_FCTR: descriptors have this norm

int resolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Runs fn(begin, end) over [0, n) split into `threads` contiguous chunks.
template <typename Fn>
void parallelChunks(size_t n, int threads, Fn fn) {
  if (threads <= 1 || n < 4096) {
    fn(size_t(0), n);
    return;
  }
  std::vector<std::thread> pool;
  const size_t chunk = (n + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    const size_t b = t * chunk, e = std::min(n, b + chunk);
    if (b >= e) break;
    pool.emplace_back([=, &fn] { fn(b, e); });
  }
  for (auto& th : pool) th.join();
}

// Squared distance D² used by k-means++ seeding: for SIFT the squared chord between the unit
// directions, 2(1 − cos) (the angle metric's Euclidean form), for ORB the squared Hamming distance.
struct Metric {
  DescriptorType type;
  int bytes;
  double squaredDistance(const uint8_t* x, float inv_x, const uint8_t* c, float inv_c) const {
    if (type == DescriptorType::Orb) {
      const double h = hammingDistance(x, c, bytes);
      return h * h;
    }
    return std::max(0.0, 2.0 * (1.0 - double(dotProduct(x, c, bytes)) * inv_x * inv_c));
  }
};

}  // namespace

float inverseNorm(const uint8_t* centre, int bytes) {
  const double n2 = dotProduct(centre, centre, bytes);
  return n2 > 0 ? static_cast<float>(1.0 / std::sqrt(n2)) : 0.f;
}

KMeansResult kmeans(const DescriptorSet& set, const std::vector<uint32_t>& points, DescriptorType type, uint32_t k, int max_iterations,
                    uint64_t seed, int threads) {
  const int bytes = set.bytes;
  const size_t n = points.size();
  KMeansResult r;
  r.bytes_ = bytes;
  if (n == 0 || k == 0) return r;
  const Metric metric{type, bytes};
  std::vector<float> inv_x(n, 1.f);
  if (type == DescriptorType::Sift)
    for (size_t i = 0; i < n; ++i) inv_x[i] = inverseNorm(set.row(points[i]), bytes);

  // --- k-means++ seeding: each next centre drawn with probability ∝ D(x)², D = distance to the
  // nearest centre so far. Stops early when every point coincides with a centre.
  std::mt19937_64 rng(seed);
  std::vector<uint8_t> centres;
  std::vector<float> inv_c;
  auto addCentre = [&](size_t i) {
    const uint8_t* p = set.row(points[i]);
    centres.insert(centres.end(), p, p + bytes);
    inv_c.push_back(inv_x[i]);
  };
  addCentre(std::uniform_int_distribution<size_t>(0, n - 1)(rng));
  std::vector<double> d2(n);
  auto updateD2 = [&](size_t c, bool first) {
    const uint8_t* cp = centres.data() + c * bytes;
    parallelChunks(n, threads, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const double d = metric.squaredDistance(set.row(points[i]), inv_x[i], cp, inv_c[c]);
        d2[i] = first ? d : std::min(d2[i], d);
      }
    });
  };
  updateD2(0, true);
  while (centres.size() / bytes < k) {
    double total = 0;
    for (double v : d2) total += v;
    if (!(total > 1e-12)) break;  // fewer distinct points than k
    double target = std::uniform_real_distribution<double>(0, total)(rng), acc = 0;
    size_t pick = n - 1;
    for (size_t i = 0; i < n; ++i) {
      acc += d2[i];
      if (acc >= target && d2[i] > 0) {
        pick = i;
        break;
      }
    }
    if (d2[pick] <= 0) break;
    addCentre(pick);
    updateD2(centres.size() / bytes - 1, false);
  }
  size_t kc = centres.size() / bytes;

  // --- Lloyd iterations.
  std::vector<uint32_t> assign(n, 0xffffffffu);
  auto assignAll = [&]() -> size_t {
    std::atomic<size_t> changed{0};
    parallelChunks(n, threads, [&](size_t b, size_t e) {
      size_t ch = 0;
      for (size_t i = b; i < e; ++i) {
        const uint8_t* x = set.row(points[i]);
        uint32_t best = 0;
        if (type == DescriptorType::Sift) {
          float best_cos = -1.f;
          for (size_t c = 0; c < kc; ++c) {
            const float cos = static_cast<float>(dotProduct(x, centres.data() + c * bytes, bytes)) * inv_c[c];
            if (cos > best_cos) best_cos = cos, best = static_cast<uint32_t>(c);
          }
        } else {
          int best_d = 1 << 30;
          for (size_t c = 0; c < kc; ++c) {
            const int d = hammingDistance(x, centres.data() + c * bytes, bytes);
            if (d < best_d) best_d = d, best = static_cast<uint32_t>(c);
          }
        }
        if (assign[i] != best) ++ch, assign[i] = best;
      }
      changed += ch;
    });
    return changed;
  };
  auto updateCentres = [&] {
    std::vector<double> sums(kc * bytes * (type == DescriptorType::Orb ? 8 : 1), 0.0);
    std::vector<size_t> counts(kc, 0);
    for (size_t i = 0; i < n; ++i) {
      const uint8_t* x = set.row(points[i]);
      const size_t c = assign[i];
      ++counts[c];
      if (type == DescriptorType::Sift) {
        double* s = sums.data() + c * bytes;
        for (int j = 0; j < bytes; ++j) s[j] += x[j] * double(inv_x[i]);  // unit vectors: spherical k-means
      } else {
        double* s = sums.data() + c * bytes * 8;
        for (int j = 0; j < bytes; ++j)
          for (int b = 0; b < 8; ++b) s[j * 8 + b] += (x[j] >> (7 - b)) & 1;
      }
    }
    for (size_t c = 0; c < kc; ++c) {
      if (counts[c] == 0) continue;  // keeps its old centre; dropped at the end if still empty
      uint8_t* out = centres.data() + c * bytes;
      if (type == DescriptorType::Sift) {
        const double* s = sums.data() + c * bytes;
        double norm = 0;
        for (int j = 0; j < bytes; ++j) norm += s[j] * s[j];
        norm = std::sqrt(norm);
        if (norm <= 0) continue;
        for (int j = 0; j < bytes; ++j) out[j] = static_cast<uint8_t>(std::min(255.0, std::round(s[j] / norm * kSiftNorm)));
        inv_c[c] = inverseNorm(out, bytes);
      } else {
        const double* s = sums.data() + c * bytes * 8;
        for (int j = 0; j < bytes; ++j) {
          uint8_t v = 0;
          for (int b = 0; b < 8; ++b) v = static_cast<uint8_t>((v << 1) | (2 * s[j * 8 + b] > counts[c] ? 1 : 0));
          out[j] = v;
        }
      }
    }
  };
  int it = 0;
  for (; it < max_iterations; ++it) {
    const size_t changed = assignAll();
    if (it > 0 && changed == 0) break;
    updateCentres();
  }
  if (it == max_iterations) assignAll();  // the partition must match the final centres
  r.iterations = it;

  // Drop empty clusters and renumber.
  std::vector<size_t> counts(kc, 0);
  for (uint32_t a : assign) ++counts[a];
  std::vector<uint32_t> remap(kc, 0xffffffffu);
  uint32_t kept = 0;
  for (size_t c = 0; c < kc; ++c) {
    if (counts[c] == 0) continue;
    remap[c] = kept;
    r.centres.insert(r.centres.end(), centres.begin() + c * bytes, centres.begin() + (c + 1) * bytes);
    ++kept;
  }
  r.assignment.resize(n);
  for (size_t i = 0; i < n; ++i) r.assignment[i] = remap[assign[i]];
  return r;
}

VocabularyData buildVocabularyTree(const DescriptorSet& set, DescriptorType type, const KMeansOptions& options,
                                   const ProgressFn& progress) {
  if (options.branching < 2) throw common::InputError("branching factor k must be >= 2");
  if (options.depth < 1) throw common::InputError("depth L must be >= 1");
  if (set.count == 0) throw common::InputError("no training descriptors");
  if (set.bytes != descriptorBytes(type)) throw common::InputError("descriptor size does not match the type");
  const int bytes = set.bytes;
  const int threads = resolveThreads(options.threads);

  VocabularyData v;
  v.type = type;
  v.branching = options.branching;
  v.depth = options.depth;
  v.training_descriptors = set.count;
  auto pushNode = [&](const uint8_t* centre) {
    v.first_child.push_back(0);
    v.child_count.push_back(0);
    v.word_of_node.push_back(VocabularyData::kNoWord);
    if (centre)
      v.centres.insert(v.centres.end(), centre, centre + bytes);
    else
      v.centres.insert(v.centres.end(), bytes, 0);
    return static_cast<uint32_t>(v.first_child.size() - 1);
  };

  struct Pending {
    uint32_t node;
    std::vector<uint32_t> points;
  };
  std::vector<Pending> level;
  {
    Pending root{pushNode(nullptr), std::vector<uint32_t>(set.count)};
    for (size_t i = 0; i < set.count; ++i) root.points[i] = static_cast<uint32_t>(i);
    level.push_back(std::move(root));
  }

  for (uint32_t depth = 0; depth < options.depth && !level.empty(); ++depth) {
    std::vector<KMeansResult> results(level.size());
    std::vector<size_t> order(level.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return level[a].points.size() > level[b].points.size(); });
    std::atomic<size_t> done_points{0};
    std::mutex progress_mutex;
    auto report = [&] {
      if (!progress) return;
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress((depth + double(done_points) / set.count) / options.depth,
               "level " + std::to_string(depth + 1) + "/" + std::to_string(options.depth) + ", " + std::to_string(level.size()) + " nodes");
    };
    auto cluster = [&](size_t i, int inner_threads) {
      const Pending& p = level[i];
      if (p.points.size() > 1) {
        // Seed from the node id: results do not depend on which thread ran which node.
        const uint64_t seed = options.seed * 0x9E3779B97F4A7C15ull + p.node * 0xBF58476D1CE4E5B9ull + 1;
        results[i] = kmeans(set, p.points, type, options.branching, options.max_iterations, seed, inner_threads);
      }
      done_points += p.points.size();
      report();
    };
    // Big nodes (near the root) parallelise inside k-means; the many small ones run one per thread.
    constexpr size_t kBig = 50000;
    size_t next = 0;
    while (next < order.size() && level[order[next]].points.size() >= kBig) cluster(order[next++], threads);
    std::atomic<size_t> cursor{next};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back([&] {
        for (size_t j; (j = cursor++) < order.size();) cluster(order[j], 1);
      });
    for (auto& th : pool) th.join();

    // Children numbered in parent order: breadth-first layout with contiguous siblings.
    std::vector<Pending> next_level;
    for (size_t i = 0; i < level.size(); ++i) {
      const KMeansResult& r = results[i];
      const size_t kc = r.clusters();
      if (kc < 2) continue;  // all points identical: the node stays a leaf
      const uint32_t parent = level[i].node;
      v.first_child[parent] = static_cast<uint32_t>(v.first_child.size());
      v.child_count[parent] = static_cast<uint32_t>(kc);
      std::vector<Pending> kids(kc);
      for (size_t c = 0; c < kc; ++c) kids[c].node = pushNode(r.centres.data() + c * bytes);
      for (size_t j = 0; j < r.assignment.size(); ++j) kids[r.assignment[j]].points.push_back(level[i].points[j]);
      for (auto& kid : kids) next_level.push_back(std::move(kid));
    }
    level = std::move(next_level);
  }

  for (uint32_t node = 0; node < v.first_child.size(); ++node) {
    if (v.child_count[node] != 0) continue;
    v.word_of_node[node] = static_cast<uint32_t>(v.node_of_word.size());
    v.node_of_word.push_back(node);
  }
  v.idf.assign(v.node_of_word.size(), 0.f);
  if (type == DescriptorType::Sift) {
    v.inverse_norms.resize(v.first_child.size());
    for (size_t i = 0; i < v.inverse_norms.size(); ++i) v.inverse_norms[i] = inverseNorm(v.centres.data() + i * bytes, bytes);
  }
  if (progress) progress(1.0, "tree done");
  return v;
}

}  // namespace urbanslam::vision_loop
