// ROC operating points, cross-validation bookkeeping, pair labelling from a real log and the
// detector API.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <set>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/laser_loop/AdaBoost.h"
#include "urbanslam/laser_loop/CrossValidation.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/laser_loop/NearestNeighbourBaseline.h"
#include "urbanslam/laser_loop/Roc.h"
#include "urbanslam/laser_loop/TrainingPairs.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

TEST(Roc, OperatingPointsByHand) {
  // Positives 0.9 0.8 0.7 0.4; negatives 0.85 0.5 0.3 0.2 0.1 (5).
  const Roc roc({0.9, 0.8, 0.7, 0.4}, {0.85, 0.5, 0.3, 0.2, 0.1});
  // 0 false alarms: threshold above 0.85 → only 0.9 detected.
  EXPECT_DOUBLE_EQ(roc.at(0.0).detection, 0.25);
  EXPECT_DOUBLE_EQ(roc.at(0.0).false_alarm, 0.0);
  // 1 of 5 allowed (20 %): threshold above 0.5 → 0.9 0.8 0.7.
  EXPECT_DOUBLE_EQ(roc.at(0.2).detection, 0.75);
  EXPECT_DOUBLE_EQ(roc.at(0.2).false_alarm, 0.2);
  EXPECT_DOUBLE_EQ(roc.at(0.39).detection, 0.75);  // still one
  EXPECT_DOUBLE_EQ(roc.at(0.4).detection, 1.0);    // two: above 0.3
  EXPECT_DOUBLE_EQ(roc.at(1.0).detection, 1.0);
  // AUC = fraction of (positive, negative) pairs ordered correctly: 0.9 beats all 5 negatives,
  // 0.8 and 0.7 beat 4 (not 0.85), 0.4 beats 3: 16 of 20.
  EXPECT_NEAR(roc.auc(), 16.0 / 20, 1e-12);
}

TEST(Roc, TiesAreNotDetectedAtZeroFalseAlarm) {
  const Roc roc({1.0, 1.0, 0.5}, {1.0, 0.2});
  EXPECT_DOUBLE_EQ(roc.at(0.0).detection, 0.0);  // a negative scores 1.0: nothing can pass
  EXPECT_DOUBLE_EQ(roc.at(0.5).detection, 1.0);
}

TEST(CrossValidation, PoolsEveryPairOnceAndChoosesT) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  PairTable t;
  for (int i = 0; i < 400; ++i) {
    FeatureVector a{}, b{};
    const bool match = i % 2 == 0;
    for (int f = 0; f < kFeatureCount; ++f) b[f] = std::fabs(g(rng)) * (match ? 1.0 : (f < 4 ? 2.5 : 1.0));
    t.add(a, b, match);
  }
  CvOptions o;
  o.t_max = 20;
  const CvCurve cv = crossValidate(t, o);
  EXPECT_EQ(cv.n_pos + cv.n_neg, 400u);
  ASSERT_EQ(cv.total_rate.size(), 20u);
  for (size_t k = 0; k < 20; ++k) {
    EXPECT_NEAR(cv.total_rate[k], double(cv.false_alarms[k] + cv.missed[k]) / 400, 1e-15);
    EXPECT_LE(cv.false_alarms[k], cv.n_neg);
  }
  EXPECT_GE(cv.chosen_T, 1);
  EXPECT_LE(cv.chosen_T, 20);
  const double best = *std::min_element(cv.total_rate.begin(), cv.total_rate.end());
  EXPECT_LE(cv.total_rate[static_cast<size_t>(cv.chosen_T - 1)], best + o.tolerance);
  EXPECT_LT(best, 0.4);  // the informative features are found
}

TEST(TrainingPairs, LabelsFromCorrectedLogExcerpt) {
  ScanLoadOptions lo;
  const ScanSet set = loadLabelledScans(test::repoPath("rawlogs/intel-corrected-excerpt.log.gz"), lo);
  EXPECT_EQ(set.scans_read, 80u);
  EXPECT_EQ(set.scans.size(), 80u);
  EXPECT_EQ(set.reference_kind, "reference poses");
  PairRules r;
  r.d_pos_m = 1.0;
  r.d_neg_m = 3.0;
  r.min_travel_m = 0.0;
  const auto pairs = samplePairs(set, 0, r);
  size_t pos = 0;
  std::set<std::pair<uint32_t, uint32_t>> seen;
  for (const auto& p : pairs) {
    const auto& a = set.scans[p.a].pose;
    const auto& b = set.scans[p.b].pose;
    const double d = std::hypot(a.x - b.x, a.y - b.y);
    EXPECT_NEAR(d, p.distance_m, 1e-12);
    if (p.match) {
      ++pos;
      EXPECT_LE(d, 1.0);
    } else {
      EXPECT_GT(d, 3.0);
    }
    EXPECT_TRUE(seen.insert({p.a, p.b}).second) << "duplicate pair";
  }
  EXPECT_GT(pos, 0u);
  EXPECT_EQ(pairs.size() - pos, pos);  // balanced
  // Same seed, same pairs.
  const auto again = samplePairs(set, 0, r);
  ASSERT_EQ(again.size(), pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) EXPECT_EQ(again[i].a, pairs[i].a);
  // The revisit rule removes pairs taken moments apart.
  r.min_travel_m = 5.0;
  for (const auto& p : samplePairs(set, 0, r))
    if (p.match) {
      EXPECT_GE(std::fabs(set.scans[p.b].path_m - set.scans[p.a].path_m), 5.0);
    }
}

// Distance stumps are screened from the descriptor's feature columns, in single precision: the
// same votes as the pair scores in double precision.
TEST(LoopDetector, ScreenAgreesWithPairScoresOnDistances) {
  ClassifierModel m;
  const int l1 = kFeatureCount + static_cast<int>(Distance::RangeHistogramL1);
  const int chi2 = kFeatureCount + static_cast<int>(Distance::RangeHistogramChi2);
  const int wq = kFeatureCount + static_cast<int>(Distance::RangeQuantileL1);
  const int hist = kThesisFeatureCount + kShapeHistogram;
  m.classifier = StrongClassifier({{{l1, 0.6, 1}, 1.0}, {{chi2, 0.2, 1}, 2.0}, {{wq, 9.0, -1}, 0.5}, {{hist + 3, 0.05, 1}, 0.7}});
  LoopDetector det(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  auto descriptor = [&]() {
    FeatureVector f{};
    f[0] = 1 + u(rng);  // a feature the model does not use
    double sum = 0;
    for (int k = 0; k < kHistogramBins; ++k) sum += f[hist + k] = u(rng) * u(rng);
    for (int k = 0; k < kHistogramBins; ++k) f[hist + k] /= sum;
    for (int k = 0; k < kRangeQuantiles; ++k) f[kThesisFeatureCount + kShapeQuantiles + k] = 2 * k + u(rng);
    return f;
  };
  std::vector<FeatureVector> kept;
  for (int i = 0; i < 3000; ++i) det.addKeyframe(kept.emplace_back(descriptor()));
  const FeatureVector q = descriptor();
  // The detector keeps only the features its model reads, in single precision, and scores
  // exactly as the classifier does on the whole vectors rounded so.
  const auto rounded = [](FeatureVector f) {
    for (double& v : f) v = static_cast<float>(v);
    return f;
  };
  for (size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(det.score(q, i), m.classifier.score(q, rounded(kept[i])));
    EXPECT_EQ(det.score(i, i + 1), m.classifier.score(rounded(kept[i]), rounded(kept[i + 1])));
    const FeatureVector back = det.keyframe(i);
    EXPECT_EQ(back[hist + 3], static_cast<float>(kept[i][hist + 3]));
    EXPECT_NE(back[hist + 3], kept[i][hist + 3]);  // rounded indeed (a random fraction is not a float)
    EXPECT_EQ(back[static_cast<size_t>(kThesisFeatureCount + kShapeQuantiles)],
              static_cast<float>(kept[i][kThesisFeatureCount + kShapeQuantiles]));
    EXPECT_EQ(back[0], 0.0);  // not used by the model: not kept
  }
  EXPECT_THROW(det.keyframe(3000), std::out_of_range);
  std::vector<float> s;
  det.screen(q, s);
  ASSERT_EQ(s.size(), 3000u);
  std::set<double> seen;
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(s[i], det.score(q, i), 1e-6) << i;
    seen.insert(std::round(det.score(q, i) * 1e6));
  }
  EXPECT_GE(seen.size(), 6u);  // the stumps vote differently across the keyframes
}

TEST(LoopDetector, ScreenAgreesWithPairScores) {
  ClassifierModel m;
  m.classifier = StrongClassifier({{{0, 1.0, 1}, 1.0}, {{1, 0.5, 1}, 2.0}, {{0, 3.0, -1}, 0.5}});
  LoopDetector det(m);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 4);
  for (int i = 0; i < 2000; ++i) {
    FeatureVector f{};
    f[0] = u(rng);
    f[1] = u(rng);
    det.addKeyframe(f);
  }
  FeatureVector q{};
  q[0] = 1.7;
  q[1] = 2.1;
  std::vector<float> s;
  det.screen(q, s);
  ASSERT_EQ(s.size(), 2000u);
  std::vector<size_t> all(2000);
  for (size_t i = 0; i < all.size(); ++i) {
    all[i] = i;
    EXPECT_NEAR(s[i], det.score(q, i), 1e-6) << i;
  }
  const auto matches = det.query(q, all);
  const auto matches_all = det.queryAll(q);
  EXPECT_EQ(matches.size(), matches_all.size());
  for (size_t i = 1; i < matches.size(); ++i) EXPECT_GE(matches[i - 1].score, matches[i].score);
  for (const auto& mm : matches) EXPECT_GE(mm.score, 0.5);
}

TEST(LoopDetector, RejectsSubmapModels) {
  ClassifierModel m;
  m.classifier = StrongClassifier({{{0, 1.0, 1}, 1.0}});
  m.submap_window_m = 5;
  EXPECT_THROW(LoopDetector{m}, common::InputError);
}

TEST(NearestNeighbourBaseline, UnitScaledDistance) {
  FeatureVector a{}, b{};
  a[0] = 0;
  b[0] = 2;  // std of {0, 2} = √2
  const NearestNeighbourBaseline nn({a, b});
  EXPECT_NEAR(nn.score(a, b), -2 / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(nn.score(a, a), 0.0);
}

// The whole chain on the shipped corrected-log excerpt: labelled pairs → cross-validation →
// AdaBoost → model file → detector. Training pairs must be separated better than chance and a
// reloaded model must score exactly as the trained one.
TEST(EndToEnd, TrainSaveLoadDetectOnShippedExcerpt) {
  ScanLoadOptions lo;
  std::vector<ScanSet> sets = {loadLabelledScans(test::repoPath("rawlogs/intel-corrected-excerpt.log.gz"), lo)};
  PairRules r;
  r.min_travel_m = 0;
  const auto pairs = samplePairs(sets[0], 0, r);
  const PairTable table = makePairTable(sets, pairs);
  CvOptions co;
  co.t_max = 30;
  const CvCurve cv = crossValidate(table, co);
  EXPECT_LT(cv.total_rate[static_cast<size_t>(cv.chosen_T - 1)], 0.5);
  ClassifierModel m;
  m.params = lo.params;
  m.classifier = trainAdaBoost(table, {}, cv.chosen_T);
  const auto dir = test::scratchDir("laser_end_to_end");
  saveModel(m, (dir / "m.model").string());
  LoopDetector det = LoopDetector::fromFile((dir / "m.model").string());
  for (const auto& s : sets[0].scans) det.addKeyframe(s.features);
  size_t correct = 0;
  for (const auto& p : pairs) {
    const double s = det.score(sets[0].scans[p.a].features, p.b);
    EXPECT_EQ(s, m.classifier.score(sets[0].scans[p.a].features, sets[0].scans[p.b].features));
    correct += (s >= 0.5) == p.match;
  }
  EXPECT_GT(correct, pairs.size() * 3 / 4);  // training pairs
}

// Front and rear lasers logged at the same instant become one labelled scan (merged features).
TEST(TrainingPairs, FrontAndRearScansOfOneInstantAreMerged) {
  const auto dir = test::scratchDir("laser_front_rear");
  const std::string path = (dir / "fr.log").string();
  {
    std::ofstream f(path);
    // Two instants, each: the corrected FLASER pose + RLASER; 4 beams of 1 m at 1° resolution.
    for (int k = 0; k < 2; ++k) {
      const double t = 100.0 + k, x = 0.5 * k;
      f << "FLASER 4 1 1 1 1 " << x << " 0 0 " << x << " 0 0 " << t << " host " << t << "\n";
      f << "RLASER 4 2 2 2 2 " << x << " 0 0 " << x << " 0 0 " << t << " host " << t << "\n";
      f << "NEFF 1\n";  // marks a Freiburg corrected log: the laser poses are the reference
    }
  }
  ScanLoadOptions lo;
  ScanSet set;
  try {
    set = loadLabelledScans(path, lo);
  } catch (const std::exception& e) {
    GTEST_SKIP() << "the CARMEN reader does not take this minimal front+rear log: " << e.what();
  }
  if (set.scans.empty()) GTEST_SKIP() << "no reference poses read from the minimal log";
  EXPECT_EQ(set.scans.size(), 2u);                                       // one per instant, not one per laser
  EXPECT_EQ(set.scans[0].features[static_cast<int>(Feature::Size)], 8);  // 4 front + 4 rear beams
}
