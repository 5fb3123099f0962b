// The sequence score against its definition (SequenceScore.h), by hand and by brute force over
// a dense score matrix.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "urbanslam/common/Error.h"
#include "urbanslam/vision_loop/SequenceScore.h"

using namespace urbanslam::vision_loop;

TEST(SequenceScore, MeanOfTheBestScoresInTheConeOfEachEarlierQuery) {
  SequenceScore s(4);
  s.push({{5, 0.4f}});             // three queries back: cone [4, 9]
  s.push({{8, 0.6f}, {7, 0.9f}});  // two back: cone [6, 9]
  s.push({{3, 0.2f}, {9, 0.8f}});  // one back: cone [8, 9]
  EXPECT_FLOAT_EQ(s.score(10, 1.0f), (1.0f + 0.8f + 0.9f + 0.4f) / 4);
  // Image 6: one back [4, 5] has nothing; two back [2, 5] nothing; three back [0, 5] has 5.
  EXPECT_FLOAT_EQ(s.score(6, 0.5f), (0.5f + 0.4f) / 4);
}

TEST(SequenceScore, AnImageThatMatchesEveryQueryGetsNoSupport) {
  // A hub: the same database image is the best match of every query of a stretch. A revisit
  // advances through the database; standing still is not one.
  SequenceScore s(5);
  for (int i = 0; i < 4; ++i) s.push({{10, 2.0f}});
  EXPECT_FLOAT_EQ(s.score(10, 2.0f), 2.0f / 5);
  // The same queries matching frames 6, 7, 8, 9 in turn: full support for 10.
  SequenceScore t(5);
  for (ImageId i : {6u, 7u, 8u, 9u}) t.push({{i, 2.0f}});
  EXPECT_FLOAT_EQ(t.score(10, 2.0f), 2.0f);
}

TEST(SequenceScore, EqualsBruteForceOnRandomScores) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1.5f);
  const int frames = 6, queries = 40, images = 60;
  // eta[q][i]: query q's score of image i, 0 when i was not among its (sparse) results.
  std::vector<std::vector<float>> eta(queries, std::vector<float>(images, 0));
  SequenceScore s(frames);
  for (int q = 0; q < queries; ++q) {
    std::vector<ScoredImage> results;
    for (int i = 0; i < images; ++i)
      if (rng() % 4 == 0) eta[q][i] = u(rng), results.push_back({static_cast<ImageId>(i), eta[q][i]});
    std::shuffle(results.begin(), results.end(), rng);
    if (q == queries - 1) {
      for (int j = 0; j < images; ++j) {
        float sum = eta[q][j];
        for (int k = 1; k < frames; ++k) {
          float best = 0;
          for (int i = std::max(0, j - 2 * k); i <= j - std::max(1, k / 2); ++i) best = std::max(best, eta[q - k][i]);
          sum += best;
        }
        EXPECT_NEAR(s.score(static_cast<ImageId>(j), eta[q][j]), sum / frames, 1e-5f) << "image " << j;
      }
    }
    s.push(results);
  }
}

TEST(SequenceScore, OneFrameIsThePresentScoreAndOldQueriesDropOut) {
  SequenceScore one(1);
  one.push({{3, 0.9f}});
  EXPECT_FLOAT_EQ(one.score(4, 0.7f), 0.7f);
  SequenceScore two(2);
  two.push({{3, 0.9f}});
  two.push({});  // a frame that was not queried
  EXPECT_FLOAT_EQ(two.score(4, 0.7f), 0.7f / 2);
  EXPECT_THROW(SequenceScore(0), urbanslam::common::InputError);
}
