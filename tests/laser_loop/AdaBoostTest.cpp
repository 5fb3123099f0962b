// Decision stumps and Algorithm 1, against rounds worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "urbanslam/laser_loop/AdaBoost.h"

using namespace urbanslam::laser_loop;

namespace {

// A table whose pair distances are given directly: feature 0 = c0, feature 1 = c1, the rest 0.
PairTable table(const std::vector<double>& c0, const std::vector<double>& c1, const std::vector<int>& y) {
  PairTable t;
  for (size_t i = 0; i < y.size(); ++i) {
    FeatureVector a{}, b{};
    b[0] = c0[i];
    b[1] = c1.empty() ? 0 : c1[i];
    t.add(a, b, y[i] != 0);
  }
  return t;
}

size_t trainingErrors(const PairTable& t, const StrongClassifier& s) {
  size_t errors = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    FeatureVector a{}, b{};
    for (int f = 0; f < kFeatureCount; ++f) b[f] = t.c[f][i];
    errors += s.match(a, b) != (t.y[i] != 0);
  }
  return errors;
}

}  // namespace

TEST(WeakClassifier, PairDistanceIsAbsoluteDifference) {
  PairTable t;
  FeatureVector a{}, b{};
  a[3] = 2.5;
  b[3] = 4.0;
  t.add(a, b, true);
  t.add(b, a, false);
  EXPECT_DOUBLE_EQ(t.c[3][0], 1.5);
  EXPECT_DOUBLE_EQ(t.c[3][1], 1.5);
  Stump s{3, 2.0, 1};
  EXPECT_TRUE(s.match(a, b));
  s.polarity = -1;
  EXPECT_FALSE(s.match(a, b));
}

TEST(WeakClassifier, StumpMinimisesWeightedError) {
  // Positives at 0.1, 0.2, 0.3, 0.9, negatives at 0.5, 0.8; weights 1/8 and 1/4.
  const PairTable t = table({0.1, 0.2, 0.3, 0.9, 0.5, 0.8}, {}, {1, 1, 1, 1, 0, 0});
  std::vector<uint32_t> order = {0, 1, 2, 4, 5, 3};
  const std::vector<double> w = {0.125, 0.125, 0.125, 0.125, 0.25, 0.25};
  const StumpFit fit = fitStump(t, 0, order, w);
  EXPECT_EQ(fit.stump.polarity, 1);
  EXPECT_DOUBLE_EQ(fit.stump.threshold, 0.4);  // midway between 0.3 and 0.5
  EXPECT_DOUBLE_EQ(fit.error, 0.125);          // only the positive at 0.9 is missed
}

// Algorithm 1 on the set above, two rounds by hand:
// round 1: W̃ = 1/8 (pos), 1/4 (neg); stump c0 < 0.4, ε = 1/8, β = 1/7, α = log 7; correct pairs
//          scaled by 1/7 → W = 1/56,1/56,1/56,1/8 | 1/28,1/28.
// round 2: W̃ = W / (1/4) = 1/14,1/14,1/14,1/2 | 1/7,1/7; best stump c0 > 0.85 (polarity −1),
//          missing the three close positives: ε = 3/14, β = 3/11.
TEST(AdaBoost, FollowsAlgorithm1ExactlyByHand) {
  const PairTable t = table({0.1, 0.2, 0.3, 0.9, 0.5, 0.8}, {}, {1, 1, 1, 1, 0, 0});
  AdaBoostTrainer trainer(t, {}, true);
  ASSERT_TRUE(trainer.round());
  const auto& r1 = trainer.rounds()[0];
  const std::vector<double> w1 = {0.125, 0.125, 0.125, 0.125, 0.25, 0.25};
  for (size_t i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r1.normalised_weights[i], w1[i]) << i;
  EXPECT_EQ(r1.chosen.stump.comparison, 0);
  EXPECT_EQ(r1.chosen.stump.polarity, 1);
  EXPECT_DOUBLE_EQ(r1.chosen.stump.threshold, 0.4);
  EXPECT_DOUBLE_EQ(r1.error, 0.125);
  EXPECT_DOUBLE_EQ(r1.beta, 1.0 / 7);
  EXPECT_NEAR(r1.chosen.alpha, std::log(7.0), 1e-12);
  const std::vector<double> w2_unnorm = {1.0 / 56, 1.0 / 56, 1.0 / 56, 1.0 / 8, 1.0 / 28, 1.0 / 28};
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(trainer.weights()[i], w2_unnorm[i], 1e-15) << i;

  ASSERT_TRUE(trainer.round());
  const auto& r2 = trainer.rounds()[1];
  const std::vector<double> w2 = {1.0 / 14, 1.0 / 14, 1.0 / 14, 0.5, 1.0 / 7, 1.0 / 7};
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(r2.normalised_weights[i], w2[i], 1e-15) << i;
  EXPECT_EQ(r2.chosen.stump.comparison, 0);
  EXPECT_EQ(r2.chosen.stump.polarity, -1);
  EXPECT_NEAR(r2.chosen.stump.threshold, 0.85, 1e-15);
  EXPECT_NEAR(r2.error, 3.0 / 14, 1e-15);
  EXPECT_NEAR(r2.beta, 3.0 / 11, 1e-15);
  EXPECT_NEAR(r2.chosen.alpha, std::log(11.0 / 3), 1e-12);
}

TEST(AdaBoost, SingleStumpSeparableSetStopsWithZeroError) {
  const PairTable t = table({0.1, 0.2, 0.3, 0.5, 0.6, 0.7}, {}, {1, 1, 1, 0, 0, 0});
  AdaBoostTrainer trainer(t, {});
  trainer.run(10);
  EXPECT_TRUE(trainer.finished());
  ASSERT_EQ(trainer.classifier().size(), 1u);
  EXPECT_EQ(trainer.rounds()[0].error, 0.0);
  EXPECT_TRUE(std::isfinite(trainer.classifier().stumps()[0].alpha));
  EXPECT_EQ(trainingErrors(t, trainer.classifier()), 0u);
}

// Positives are close in both features, negatives far in one of them: no single stump separates
// them, a weighted vote of several does, and boosting reaches zero training error.
TEST(AdaBoost, SeparableToySetReachesZeroTrainingError) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> close(0.0, 0.9), far(1.1, 3.0);
  std::vector<double> c0, c1;
  std::vector<int> y;
  for (int i = 0; i < 40; ++i) {
    c0.push_back(close(rng));
    c1.push_back(close(rng));
    y.push_back(1);
  }
  for (int i = 0; i < 60; ++i) {
    const int kind = i % 3;
    c0.push_back(kind == 1 ? close(rng) : far(rng));
    c1.push_back(kind == 0 ? close(rng) : far(rng));
    y.push_back(0);
  }
  const PairTable t = table(c0, c1, y);
  AdaBoostTrainer one(t, {});
  one.run(1);
  EXPECT_GT(trainingErrors(t, one.classifier()), 0u);
  AdaBoostTrainer trainer(t, {});
  trainer.run(30);
  EXPECT_EQ(trainingErrors(t, trainer.classifier()), 0u);
  // Every round's error is a proper weighted error below chance.
  for (const auto& r : trainer.rounds()) {
    EXPECT_GE(r.error, 0.0);
    EXPECT_LT(r.error, 0.5);
  }
}

TEST(AdaBoost, NeedsBothClasses) {
  const PairTable t = table({0.1, 0.2}, {}, {1, 1});
  EXPECT_THROW(AdaBoostTrainer(t, {}), std::exception);
}

TEST(StrongClassifier, FactorTradesDetectionForFalseAlarm) {
  StrongClassifier s({{{0, 1.0, 1}, 2.0}, {{1, 1.0, 1}, 1.0}});
  FeatureVector a{}, b{};
  b[0] = 0.5;  // stump 0 says match, stump 1 (c1 = 0 < 1) says match
  EXPECT_DOUBLE_EQ(s.score(a, b), 1.0);
  b[1] = 2.0;  // only stump 0: 2/3
  EXPECT_NEAR(s.score(a, b), 2.0 / 3, 1e-15);
  EXPECT_TRUE(s.match(a, b, 0.5));
  EXPECT_FALSE(s.match(a, b, 0.7));
  EXPECT_EQ(s.prefix(1).size(), 1u);
  EXPECT_DOUBLE_EQ(s.prefix(1).score(a, b), 1.0);
}

// score() uses sorted thresholds and α sums per feature; it must equal the plain vote of 3.30.
TEST(StrongClassifier, FastScoreEqualsPlainVote) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> feat(0, kFeatureCount - 1);
  std::uniform_real_distribution<double> u(0, 2);
  std::vector<WeightedStump> stumps;
  for (int t = 0; t < 120; ++t) {
    // A few thresholds repeat exactly, to exercise ties with c.
    const double thr = t % 10 == 0 ? 1.0 : u(rng);
    stumps.push_back({{feat(rng), thr, rng() % 2 ? 1 : -1}, u(rng)});
  }
  const StrongClassifier s(stumps);
  for (int k = 0; k < 500; ++k) {
    FeatureVector a{}, b{};
    for (int f = 0; f < kFeatureCount; ++f) {
      a[f] = u(rng);
      b[f] = k % 7 == 0 ? a[f] + 1.0 : u(rng);  // c exactly at the repeated threshold
    }
    double vote = 0, total = 0;
    for (const auto& w : stumps) {
      total += w.alpha;
      if (w.stump.match(a, b)) vote += w.alpha;
    }
    EXPECT_NEAR(s.score(a, b), vote / total, 1e-12) << k;
  }
}
