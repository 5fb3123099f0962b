#include <gtest/gtest.h>

#include <random>

#include "urbanslam/vision_loop/ImageDatabase.h"

using namespace urbanslam::vision_loop;

namespace {

BagOfWords randomBag(std::mt19937_64& rng, size_t words, int entries) {
  std::vector<WordWeight> raw;
  std::uniform_real_distribution<float> w(0.01f, 1.f);
  for (int i = 0; i < entries; ++i) raw.push_back({static_cast<WordId>(rng() % words), w(rng)});
  return makeBagOfWords(raw);
}

}  // namespace

TEST(BagOfWords, NormalisedSortedAndMerged) {
  const BagOfWords b = makeBagOfWords({{5, 1.f}, {2, 2.f}, {5, 1.f}, {9, 0.f}});
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b.entries[0].word, 2u);
  EXPECT_FLOAT_EQ(b.entries[0].weight, 0.5f);
  EXPECT_FLOAT_EQ(b.entries[1].weight, 0.5f);
}

TEST(ImageDatabase, InvertedFileScoreEqualsBruteForceL1) {
  std::mt19937_64 rng(4);
  const size_t words = 500;
  ImageDatabase db(words);
  std::vector<BagOfWords> bags;
  for (int i = 0; i < 300; ++i) {
    bags.push_back(randomBag(rng, words, 5 + static_cast<int>(rng() % 80)));
    db.add(bags.back());
  }
  for (int q = 0; q < 20; ++q) {
    const BagOfWords query = randomBag(rng, words, 60);
    const std::vector<float> fast = db.scoreAll(query);
    std::vector<QueryResult> brute;
    for (size_t i = 0; i < bags.size(); ++i) {
      const float s = l1Score(query, bags[i]);
      EXPECT_NEAR(fast[i], s, 2e-5f) << "image " << i;
      if (s > 0) brute.push_back({static_cast<ImageId>(i), s});
    }
    QueryOptions o;
    o.max_results = 15;
    const auto top = db.query(query, o);
    std::sort(brute.begin(), brute.end(), [](auto& a, auto& b) { return a.score > b.score; });
    ASSERT_EQ(top.size(), 15u);
    for (size_t i = 0; i < top.size(); ++i) EXPECT_NEAR(top[i].score, brute[i].score, 2e-5f);
    for (size_t i = 1; i < top.size(); ++i) EXPECT_GE(top[i - 1].score, top[i].score);
  }
}

TEST(ImageDatabase, IdenticalBagScoresOneAndBestScoresAreSymmetricAndInRange) {
  std::mt19937_64 rng(8);
  ImageDatabase db(1000);
  std::vector<BagOfWords> bags;
  for (int i = 0; i < 100; ++i) {
    bags.push_back(randomBag(rng, 1000, 40));
    db.add(bags.back());
  }
  for (int i = 0; i < 100; i += 7) {
    const auto top = db.query(bags[i]);
    ASSERT_FALSE(top.empty());
    EXPECT_EQ(top[0].image, static_cast<ImageId>(i));
    EXPECT_NEAR(top[0].score, 1.f, 1e-5f);
    for (int j = 0; j < 100; j += 13) {
      const float a = l1Score(bags[i], bags[j]), b = l1Score(bags[j], bags[i]);
      EXPECT_FLOAT_EQ(a, b);
      EXPECT_GE(a, 0.f);
      EXPECT_LE(a, 1.f);
      EXPECT_NEAR(db.scoreAll(bags[i])[j], db.scoreAll(bags[j])[i], 1e-6f);
    }
  }
  EXPECT_FLOAT_EQ(l1Score(makeBagOfWords({{1, 1.f}}), makeBagOfWords({{2, 1.f}})), 0.f);
}

TEST(ImageDatabase, QueryRestrictedToCandidatesAndOlderImages) {
  std::mt19937_64 rng(5);
  ImageDatabase db(200);
  std::vector<BagOfWords> bags;
  for (int i = 0; i < 50; ++i) {
    bags.push_back(randomBag(rng, 200, 30));
    db.add(bags.back());
  }
  const std::vector<ImageId> candidates = {3, 17, 40, 44};
  QueryOptions o;
  o.max_results = 50;
  o.candidates = &candidates;
  o.max_image = 42;
  const auto r = db.query(bags[17], o);
  ASSERT_FALSE(r.empty());
  EXPECT_EQ(r[0].image, 17u);
  for (const auto& x : r) EXPECT_TRUE(x.image == 3 || x.image == 17 || x.image == 40) << x.image;
  // Scratch buffers are reset: an unrestricted query afterwards sees everything again.
  QueryOptions all;
  all.max_results = 100;
  EXPECT_GT(db.query(bags[17], all).size(), 4u);
  EXPECT_EQ(db.query(bags[17], all)[0].image, 17u);
}

#include "urbanslam/vision_loop/CandidateSelection.h"

TEST(CandidateSelection, GatesByMahalanobisDistanceBeyondViewRange) {
  using urbanslam::common::Pose2;
  const std::vector<Pose2> poses = {{0, 0, 0}, {10, 0, 0}, {20, 0, 0}, {0, 40, 0}};
  // Image 3 is uncertain along y only: 35 m beyond view range / σ_y = 20 m → m² ≈ 3.1, inside.
  const std::vector<PositionCovariance> cov = {{1, 0, 1}, {1, 0, 1}, {1, 0, 1}, {1, 0, 400}};
  CandidateGateOptions o;
  o.view_range_m = 5;
  const auto c = selectCandidates(poses, cov, Pose2{1, 0, 0}, o);
  // Image 0 (1 m away), image 1 (9 m: 4 m beyond range, m² = 16 > 9.21 → out), image 2 far, image 3 in.
  EXPECT_EQ(c, (std::vector<ImageId>{0, 3}));
  o.chi2_gate = 20;
  EXPECT_EQ(selectCandidates(poses, cov, Pose2{1, 0, 0}, o), (std::vector<ImageId>{0, 1, 3}));
}
