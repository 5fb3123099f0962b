// Model file: save/load round trip and clear errors for malformed files.
#include <gtest/gtest.h>

#include <fstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/laser_loop/ClassifierModel.h"
#include "urbanslam/laser_loop/Comparisons.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

namespace {

ClassifierModel sample() {
  ClassifierModel m;
  m.params.r_max_m = 27.5;
  m.params.g_max_dist_m = 1.25;
  m.params.g_min_size = 4;
  m.params.log_features = true;
  m.submap_window_m = 7.5;
  m.factor = 0.45;
  m.comments = {"command: urbanslam train-laser-loop a.log --out m.model"};
  m.provenance = {{"data", "a.log b.log"}, {"pairs", "120 positive, 120 negative"}};
  m.classifier = StrongClassifier({{{static_cast<int>(Feature::Area), 1.0 / 3, 1}, 0.1 + 0.2},
                                   {{static_cast<int>(Feature::StdRange), 12345.678901234567, -1}, 2.5e-7}});
  return m;
}

std::string modelWith(const std::string& from, const std::string& to) {
  std::string t = modelToText(sample());
  const auto at = t.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return t.replace(at, from.size(), to);
}

std::string featuresLine() { return "features " + std::to_string(kFeatureCount); }

std::string errorOf(const std::string& text) {
  try {
    parseModel(text, "m.model");
  } catch (const common::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(ClassifierModel, SaveLoadRoundTripIsExact) {
  const auto dir = test::scratchDir("laser_model_roundtrip");
  const std::string path = (dir / "m.model").string();
  const ClassifierModel m = sample();
  saveModel(m, path);
  const ClassifierModel r = loadModel(path);
  EXPECT_EQ(r.params.r_max_m, m.params.r_max_m);
  EXPECT_EQ(r.params.g_max_dist_m, m.params.g_max_dist_m);
  EXPECT_EQ(r.params.g_min_size, m.params.g_min_size);
  EXPECT_EQ(r.params.log_features, true);
  EXPECT_EQ(r.submap_window_m, 7.5);
  EXPECT_EQ(r.factor, m.factor);
  EXPECT_EQ(r.comments, m.comments);
  EXPECT_EQ(r.provenance, m.provenance);
  ASSERT_EQ(r.classifier.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(r.classifier.stumps()[i].stump.comparison, m.classifier.stumps()[i].stump.comparison);
    EXPECT_EQ(r.classifier.stumps()[i].stump.threshold, m.classifier.stumps()[i].stump.threshold);  // bit-exact
    EXPECT_EQ(r.classifier.stumps()[i].stump.polarity, m.classifier.stumps()[i].stump.polarity);
    EXPECT_EQ(r.classifier.stumps()[i].alpha, m.classifier.stumps()[i].alpha);
  }
  EXPECT_EQ(modelToText(r), modelToText(m));
  EXPECT_EQ(r.provenanceValue("pairs"), "120 positive, 120 negative");
}

// Models written before log_features existed have no such line: they compare the plain features.
TEST(ClassifierModel, ModelWithoutLogFeaturesKeyUsesPlainFeatures) {
  EXPECT_FALSE(parseModel(modelWith("log_features 1\n", ""), "m.model").params.log_features);
  EXPECT_EQ(parseModel(modelWith("submap_window_m 7.5\n", ""), "m.model").submap_window_m, 0.0);
  EXPECT_NE(errorOf(modelWith("submap_window_m 7.5", "submap_window_m -1")).find("submap_window_m must be >= 0"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("log_features 1", "log_features yes")).find("log_features must be 0 or 1"), std::string::npos);
}

TEST(ClassifierModel, MalformedFilesGiveClearErrors) {
  EXPECT_NE(errorOf("").find("empty file"), std::string::npos);
  EXPECT_NE(errorOf("hello 1\n").find("m.model:1: not a laser loop-closure model"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("urbanslam-laser-loop-model 1", "urbanslam-laser-loop-model 7")).find("version 7 is not supported"),
            std::string::npos);
  EXPECT_NE(errorOf(modelWith("end\n", "")).find("truncated"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("r_max_m 27.5", "r_max_m abc")).find("r_max_m: 'abc' is not a finite number"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("r_max_m 27.5\n", "")).find("missing required key(s): r_max_m"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("factor", "fudge")).find("unknown key 'fudge'"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("stumps 2", "stumps 3")).find("'stumps 3' declared but 2 stump lines"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("stump area", "stump areal")).find("unknown feature or distance 'areal'"), std::string::npos);
  EXPECT_NE(errorOf(modelWith(" +1 ", " +2 ")).find("polarity must be +1 or -1"), std::string::npos);
  EXPECT_NE(errorOf(modelWith(featuresLine() + " area", featuresLine() + " size")).find("different feature set"), std::string::npos);
  EXPECT_NE(errorOf(modelWith(featuresLine(), "features 500")).find("the model has 500 features"), std::string::npos);
  EXPECT_NE(errorOf(modelWith("end\n", "end\nstump area 1 +1 1\n")).find("text after 'end'"), std::string::npos);
  // The line number points at the culprit.
  EXPECT_NE(errorOf(modelWith("g_min_size 4", "g_min_size 4.5")).find("m.model:5:"), std::string::npos);
}

// Features are only appended, so a model that lists the thesis's twenty (written before the shape
// descriptors existed) still loads; a stump on something its list lacks does not.
TEST(ClassifierModel, OlderModelsListAPrefixOfTheFeatures) {
  std::string thesis = "features " + std::to_string(kThesisFeatureCount);
  for (int i = 0; i < kThesisFeatureCount; ++i) thesis += std::string(" ") + featureName(i);
  std::string full = featuresLine();
  for (int i = 0; i < kFeatureCount; ++i) full += std::string(" ") + featureName(i);
  const ClassifierModel old = parseModel(modelWith(full, thesis), "m.model");
  EXPECT_EQ(old.classifier.size(), 2u);
  EXPECT_NE(errorOf(modelWith(full + "\nstumps 2\nstump area", thesis + "\nstumps 2\nstump range_q50")).find("does not list"),
            std::string::npos);
  EXPECT_NE(errorOf(modelWith(full + "\nstumps 2\nstump area", thesis + "\nstumps 2\nstump range_hist_l1")).find("does not list"),
            std::string::npos);
}

// A distance stump (Comparisons.h) is saved by name and read back as the same comparison.
TEST(ClassifierModel, DistanceStumpsRoundTrip) {
  ClassifierModel m = sample();
  m.classifier = StrongClassifier({{{kFeatureCount + static_cast<int>(Distance::RangeHistogramChi2), 0.25, 1}, 1.5},
                                   {{kThesisFeatureCount + kShapeQuantiles, 3.0, -1}, 0.5}});
  const std::string text = modelToText(m);
  EXPECT_NE(text.find("stump range_hist_chi2 0.25 +1 1.5"), std::string::npos);
  EXPECT_NE(text.find("stump range_q05 3 -1 0.5"), std::string::npos);
  const ClassifierModel r = parseModel(text, "m.model");
  EXPECT_EQ(r.classifier.stumps()[0].stump.comparison, kFeatureCount + 2);
  EXPECT_EQ(r.classifier.stumps()[1].stump.comparison, kThesisFeatureCount + kShapeQuantiles);
}

TEST(ClassifierModel, MissingFileNamesThePath) {
  try {
    loadModel("/nonexistent/x.model");
    FAIL();
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.model"), std::string::npos);
  }
}

TEST(ClassifierModel, ShippedDefaultModelLoads) {
  const std::string path = test::repoPath("share/laser_loop/default.model");
  std::ifstream probe(path);
  if (!probe) GTEST_SKIP() << "share/laser_loop/default.model not trained yet";
  const ClassifierModel m = loadModel(path);
  EXPECT_GT(m.classifier.size(), 0u);
  EXPECT_FALSE(m.provenanceValue("data").empty());
}
