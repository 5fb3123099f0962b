#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "urbanslam/vision_loop/HierarchicalKMeans.h"
#include "urbanslam/vision_loop/VocabularyTrainer.h"

using namespace urbanslam::vision_loop;

namespace {

// SIFT-like clusters: cluster c puts its energy on its own block of dimensions, plus noise.
std::vector<uint8_t> siftClusters(int clusters, int per_cluster, std::vector<int>& labels, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> noise(0, 12);
  const int block = 128 / clusters;
  std::vector<uint8_t> data;
  for (int c = 0; c < clusters; ++c)
    for (int i = 0; i < per_cluster; ++i) {
      for (int j = 0; j < 128; ++j) data.push_back(static_cast<uint8_t>((j / block == c ? 90 : 0) + noise(rng)));
      labels.push_back(c);
    }
  return data;
}

// ORB-like clusters: random 256-bit centres, members flip a few random bits.
std::vector<uint8_t> orbClusters(int clusters, int per_cluster, std::vector<int>& labels, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<uint8_t>> centres(clusters, std::vector<uint8_t>(32));
  for (auto& c : centres)
    for (auto& b : c) b = static_cast<uint8_t>(rng());
  std::vector<uint8_t> data;
  for (int c = 0; c < clusters; ++c)
    for (int i = 0; i < per_cluster; ++i) {
      auto d = centres[c];
      for (int f = 0; f < 12; ++f) {
        const int bit = static_cast<int>(rng() % 256);
        d[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
      }
      data.insert(data.end(), d.begin(), d.end());
      labels.push_back(c);
    }
  return data;
}

// Every cluster maps to exactly one k-means cluster and vice versa.
void expectRecovered(const std::vector<int>& labels, const std::vector<uint32_t>& assignment, int clusters) {
  std::map<int, std::set<uint32_t>> found;
  std::map<uint32_t, std::set<int>> back;
  for (size_t i = 0; i < labels.size(); ++i) {
    found[labels[i]].insert(assignment[i]);
    back[assignment[i]].insert(labels[i]);
  }
  ASSERT_EQ(static_cast<int>(found.size()), clusters);
  for (const auto& [label, ks] : found) EXPECT_EQ(ks.size(), 1u) << "cluster " << label << " was split";
  for (const auto& [k, ls] : back) EXPECT_EQ(ls.size(), 1u) << "k-means cluster " << k << " mixes clusters";
}

}  // namespace

TEST(KMeans, RecoversWellSeparatedSiftClusters) {
  std::vector<int> labels;
  const auto data = siftClusters(6, 200, labels, 7);
  DescriptorSet set{data.data(), labels.size(), 128};
  std::vector<uint32_t> points(labels.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = static_cast<uint32_t>(i);
  const KMeansResult r = kmeans(set, points, DescriptorType::Sift, 6, 20, 3);
  EXPECT_EQ(r.clusters(), 6u);
  expectRecovered(labels, r.assignment, 6);
}

TEST(KMeans, RecoversWellSeparatedOrbClusters) {
  std::vector<int> labels;
  const auto data = orbClusters(8, 150, labels, 11);
  DescriptorSet set{data.data(), labels.size(), 32};
  std::vector<uint32_t> points(labels.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = static_cast<uint32_t>(i);
  const KMeansResult r = kmeans(set, points, DescriptorType::Orb, 8, 20, 5, 2);
  EXPECT_EQ(r.clusters(), 8u);
  expectRecovered(labels, r.assignment, 8);
}

TEST(KMeans, FewerDistinctPointsThanKGiveThatManyClusters) {
  std::vector<uint8_t> data;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 32; ++j) data.push_back(static_cast<uint8_t>(i % 3 == 0 ? 0 : (i % 3 == 1 ? 0xff : 0x0f)));
  DescriptorSet set{data.data(), 30, 32};
  std::vector<uint32_t> points(30);
  for (uint32_t i = 0; i < 30; ++i) points[i] = i;
  EXPECT_EQ(kmeans(set, points, DescriptorType::Orb, 10, 10, 1).clusters(), 3u);
}

TEST(VocabularyTree, DescriptorEqualToAWordCentreLandsInThatWord) {
  for (DescriptorType type : {DescriptorType::Sift, DescriptorType::Orb}) {
    std::vector<int> labels;
    const auto data = type == DescriptorType::Sift ? siftClusters(8, 60, labels, 21) : orbClusters(9, 60, labels, 23);
    const int bytes = descriptorBytes(type);
    DescriptorSet set{data.data(), labels.size(), bytes};
    KMeansOptions o;
    o.branching = 3;
    o.depth = 3;
    o.threads = 2;
    const Vocabulary v(buildVocabularyTree(set, type, o));
    ASSERT_GT(v.wordCount(), 8u);
    ASSERT_LE(v.wordCount(), 27u);
    for (WordId w = 0; w < v.wordCount(); ++w)
      EXPECT_EQ(v.quantize(v.centre(v.data().node_of_word[w])), w) << descriptorName(type) << " word " << w;
  }
}

TEST(VocabularyTree, SameSeedSameTreeWhateverTheThreadCount) {
  std::vector<int> labels;
  const auto data = siftClusters(4, 300, labels, 5);
  DescriptorSet set{data.data(), labels.size(), 128};
  KMeansOptions o;
  o.branching = 4;
  o.depth = 3;
  o.threads = 1;
  const VocabularyData a = buildVocabularyTree(set, DescriptorType::Sift, o);
  o.threads = 3;
  const VocabularyData b = buildVocabularyTree(set, DescriptorType::Sift, o);
  EXPECT_EQ(a.centres, b.centres);
  EXPECT_EQ(a.first_child, b.first_child);
}

TEST(VocabularyTree, IdfIsLnNOverNi) {
  // Two "images": word of cluster 0 occurs in both, the others in one → idf 0 and ln 2.
  std::vector<int> labels;
  const auto data = orbClusters(3, 10, labels, 2);
  cv::Mat all(30, 32, CV_8U, const_cast<uint8_t*>(data.data()));
  std::vector<cv::Mat> images = {all.rowRange(0, 20).clone(), cv::Mat()};
  cv::vconcat(all.rowRange(0, 10), all.rowRange(20, 30), images[1]);
  KMeansOptions o;
  o.branching = 3;
  o.depth = 1;
  const Vocabulary v = trainVocabulary(images, DescriptorType::Orb, o);
  ASSERT_EQ(v.wordCount(), 3u);
  const WordId w0 = v.quantize(images[0].ptr<uint8_t>(0));
  const WordId w1 = v.quantize(images[0].ptr<uint8_t>(10));
  const WordId w2 = v.quantize(images[1].ptr<uint8_t>(10));
  EXPECT_NEAR(v.idf(w0), 0.0, 1e-6);
  EXPECT_NEAR(v.idf(w1), std::log(2.0), 1e-6);
  EXPECT_NEAR(v.idf(w2), std::log(2.0), 1e-6);
  EXPECT_EQ(v.data().training_images, 2u);
}

TEST(VocabularyTree, AtMostKChildrenAndLLevelsSoQuantisationIsAtMostKLComparisons) {
  std::mt19937_64 rng(12);
  std::vector<uint8_t> data(5000 * 32);
  for (auto& b : data) b = static_cast<uint8_t>(rng());
  DescriptorSet set{data.data(), 5000, 32};
  KMeansOptions o;
  o.branching = 5;
  o.depth = 4;
  o.max_iterations = 5;
  const Vocabulary v(buildVocabularyTree(set, DescriptorType::Orb, o));
  const auto& d = v.data();
  std::vector<uint32_t> depth(d.nodeCount(), 0);
  uint32_t max_depth = 0;
  for (uint32_t n = 0; n < d.nodeCount(); ++n) {
    EXPECT_LE(d.child_count[n], 5u);
    for (uint32_t c = d.first_child[n]; c < d.first_child[n] + d.child_count[n]; ++c) {
      depth[c] = depth[n] + 1;
      max_depth = std::max(max_depth, depth[c]);
    }
  }
  EXPECT_EQ(max_depth, 4u);
  EXPECT_GT(v.wordCount(), 500u);  // 5^4 = 625 possible
  EXPECT_LE(v.wordCount(), 625u);
}
