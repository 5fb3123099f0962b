#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/RawlogWriter.h"
#include "urbanslam/vision_loop/ImageSequence.h"
#include "urbanslam/vision_loop/LoopEvaluation.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

using namespace urbanslam::vision_loop;
using urbanslam::test::repoPath;

namespace {

const std::string kExcerpt = "rawlogs/rtabmap-loop-excerpt";

std::shared_ptr<const Vocabulary> shippedVocabulary(const std::string& name) {
  return std::make_shared<const Vocabulary>(loadVocabulary(repoPath("share/vision_loop/" + name)));
}

std::vector<EvaluationFrame> excerptFrames(const Vocabulary& vocabulary, const FeatureOptions& fo) {
  FeatureExtractor extractor(fo);
  auto seq = openImageSequence(repoPath(kExcerpt));
  std::vector<EvaluationFrame> frames;
  NamedImage img;
  while (seq->next(img)) {
    EvaluationFrame f;
    f.name = img.name;
    f.features = extractor.extract(img.gray);
    f.bag = vocabulary.transform(f.features.descriptors);
    frames.push_back(std::move(f));
  }
  return frames;
}

}  // namespace

TEST(ImageSequence, FolderInNaturalOrder) {
  EXPECT_TRUE(naturalLess("2.jpg", "10.jpg"));
  EXPECT_FALSE(naturalLess("10.jpg", "2.jpg"));
  EXPECT_TRUE(naturalLess("img_007", "img_10"));
  auto seq = openImageSequence(repoPath(kExcerpt));
  EXPECT_EQ(seq->sizeHint(), 32u);
  std::vector<std::string> names;
  NamedImage img;
  while (seq->next(img)) {
    names.push_back(img.name);
    EXPECT_EQ(img.gray.type(), CV_8U);
  }
  ASSERT_EQ(names.size(), 32u);
  EXPECT_EQ(names[0], "1");
  EXPECT_EQ(names[9], "10");
  EXPECT_EQ(names[16], "41");
}

TEST(ImageSequence, RawlogImagesInFileOrder) {
  // Embedded images (CObservationImage) of a rawlog are named by their 1-based position.
  const auto dir = urbanslam::test::scratchDir("image_rawlog");
  const std::string rawlog = (dir / "images.rawlog").string();
  std::vector<cv::Mat> written;
  {
    urbanslam::io::RawlogWriter w(rawlog, urbanslam::io::RawlogLayout::Observations);
    auto seq = openImageSequence(repoPath(kExcerpt));
    NamedImage img;
    for (int i = 0; i < 3 && seq->next(img); ++i) {
      urbanslam::io::CameraImage c;
      c.timestamp = 100 + i;
      c.label = "CAMERA";
      c.width = img.gray.cols;
      c.height = img.gray.rows;
      c.pixels = std::make_shared<const std::vector<uint8_t>>(img.gray.datastart, img.gray.dataend);
      w.write(c);
      written.push_back(img.gray.clone());
    }
    w.close();
  }
  auto seq = openImageSequence(rawlog);
  NamedImage img;
  size_t n = 0;
  while (seq->next(img)) {
    ASSERT_LT(n, written.size());
    EXPECT_EQ(img.name, std::to_string(n + 1));
    EXPECT_DOUBLE_EQ(img.timestamp, 100.0 + n);
    EXPECT_EQ(cv::norm(img.gray, written[n], cv::NORM_INF), 0.0);
    ++n;
  }
  EXPECT_EQ(n, written.size());
}

TEST(GroundTruthLoops, ParsesNamesAndRejectsLonelyNames) {
  const auto gt = GroundTruthLoops::load(repoPath(kExcerpt + "/ground_truth_loops.txt"));
  EXPECT_EQ(gt.size(), 16u);
  EXPECT_TRUE(gt.isMatch("41", "1"));
  EXPECT_FALSE(gt.isMatch("41", "4"));
  EXPECT_FALSE(gt.closesLoop("1"));
  const auto dir = urbanslam::test::scratchDir("gt_bad");
  std::ofstream((dir / "bad.txt").string()) << "# comment\n12 3\n13\n";
  EXPECT_THROW(GroundTruthLoops::load((dir / "bad.txt").string()), urbanslam::common::InputError);
}

TEST(LoopDetector, IdenticalRealImageScoresBestAgainstEarlierFrames) {
  const auto vocabulary = shippedVocabulary("sift_k10_L4.usvoc");
  FeatureOptions fo;
  const auto frames = excerptFrames(*vocabulary, fo);
  ImageDatabase db(vocabulary->wordCount());
  for (const auto& f : frames) db.add(f.bag);
  for (size_t i = 0; i < frames.size(); i += 5) {
    ASSERT_FALSE(frames[i].bag.empty());
    QueryOptions o;
    o.max_results = 3;
    const auto top = db.query(frames[i].bag, o);
    ASSERT_FALSE(top.empty());
    EXPECT_EQ(top[0].image, i) << frames[i].name;
    EXPECT_NEAR(top[0].score, 1.f, 1e-4f);
    for (size_t j = 0; j < frames.size(); j += 7) {
      const float s = l1Score(frames[i].bag, frames[j].bag);
      EXPECT_FLOAT_EQ(s, l1Score(frames[j].bag, frames[i].bag));
      EXPECT_GE(s, 0.f);
      EXPECT_LE(s, 1.f);
    }
  }
}

TEST(LoopDetector, FindsTheSecondLapWithoutFalsePositives) {
  for (const char* name : {"sift_k10_L4.usvoc", "orb_k10_L4.usvoc"}) {
    const auto vocabulary = shippedVocabulary(name);
    FeatureOptions fo;
    fo.type = vocabulary->descriptorType();
    const auto frames = excerptFrames(*vocabulary, fo);
    const auto gt = GroundTruthLoops::load(repoPath(kExcerpt + "/ground_truth_loops.txt"));
    LoopDetector detector(vocabulary, fo);
    size_t tp = 0, fp = 0;
    for (const auto& f : frames) {
      const LoopResult r = detector.process(f.features, f.bag);
      if (!r.detected()) continue;
      (gt.isMatch(f.name, frames[r.match].name) ? tp : fp)++;
      EXPECT_GE(r.verification.inliers, detector.options().verification.min_inliers);
    }
    EXPECT_EQ(fp, 0u) << name;
    EXPECT_GE(tp, 8u) << name << ": of 16 loop frames";
  }
}

TEST(LoopDetector, SmallImagesFindTheSecondLapWhenUpscaledBeforeDetection) {
  // The excerpt's 512x384 frames shrunk to 160x120 (a low-resolution camera): few features
  // survive and geometric verification rejects most true loops, unless the small image is
  // upscaled before detection. Both with the default sequence matching and with DBoW2's scheme
  // (one query, the islands of two consecutive queries agreeing).
  const auto gt = GroundTruthLoops::load(repoPath(kExcerpt + "/ground_truth_loops.txt"));
  LoopDetectorOptions dbow2;
  dbow2.sequence_frames = 1;
  dbow2.temporal_consistency = 1;
  for (const char* name : {"sift_k10_L4.usvoc", "orb_k10_L4.usvoc"}) {
    const auto vocabulary = shippedVocabulary(name);
    auto count = [&](int min_side, const LoopDetectorOptions& lo) {
      FeatureOptions fo;
      fo.type = vocabulary->descriptorType();
      fo.max_image_side_px = 160;
      fo.min_image_side_px = min_side;
      const auto frames = excerptFrames(*vocabulary, fo);
      EXPECT_EQ(frames.front().features.image_size.width, min_side ? min_side : 160);
      LoopDetector detector(vocabulary, fo, lo);
      std::pair<size_t, size_t> tp_fp{0, 0};
      for (const auto& f : frames) {
        const LoopResult r = detector.process(f.features, f.bag);
        if (r.detected()) (gt.isMatch(f.name, frames[r.match].name) ? tp_fp.first : tp_fp.second)++;
      }
      return tp_fp;
    };
    for (const LoopDetectorOptions& lo : {LoopDetectorOptions{}, dbow2}) {
      const auto plain = count(0, lo), upscaled = count(320, lo);
      EXPECT_EQ(plain.second + upscaled.second, 0u) << name;
      EXPECT_GE(upscaled.first, 11u) << name << ": of 16 loop frames";
      EXPECT_GT(upscaled.first, plain.first) << name;
    }
  }
}

TEST(LoopDetector, CandidateRestrictionOnlyReturnsCandidates) {
  const auto vocabulary = shippedVocabulary("orb_k10_L4.usvoc");
  FeatureOptions fo;
  fo.type = DescriptorType::Orb;
  const auto frames = excerptFrames(*vocabulary, fo);
  LoopDetectorOptions o;
  o.temporal_consistency = 0;
  LoopDetector detector(vocabulary, fo, o);
  // Only images 10..15 (names 11..16) are plausible for the filter: frame 41 must not match 1..3.
  const std::vector<ImageId> candidates = {10, 11, 12, 13, 14, 15};
  size_t restricted_results = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const LoopResult r = detector.process(frames[i].features, frames[i].bag, i >= 16 ? &candidates : nullptr);
    if (i >= 16 && r.status != LoopStatus::NoFeatures && r.status != LoopStatus::NoCandidates && r.status != LoopStatus::DatabaseTooSmall &&
        r.status != LoopStatus::LowPriorScore) {
      ++restricted_results;
      EXPECT_TRUE(r.match >= 10 && r.match <= 15) << frames[i].name << " -> " << r.match << " (" << loopStatusName(r.status) << ")";
    }
  }
  EXPECT_GT(restricted_results, 0u);
}

TEST(LoopDetector, RefusesAVocabularyOfAnotherDescriptor) {
  const auto vocabulary = shippedVocabulary("sift_k10_L4.usvoc");
  FeatureOptions fo;
  fo.type = DescriptorType::Orb;
  EXPECT_THROW(LoopDetector(vocabulary, fo), urbanslam::common::InputError);
}

TEST(Vocabulary, ShippedTreesSendWordCentresToTheirWords) {
  // SIFT: exact, because a spherical k-means centre is the (normalised) mean of its members and
  // the angular Voronoi cell of its ancestor is a convex cone containing them all. ORB: a
  // bitwise-majority centre need not lie in its ancestor's Hamming cell, so a few percent of the
  // leaves are unreachable from their own centre (measured 95.6 % on the shipped tree).
  for (const char* name : {"sift_k10_L4.usvoc", "orb_k10_L4.usvoc"}) {
    const double required = std::string(name).rfind("sift", 0) == 0 ? 1.0 : 0.95;
    const auto v = shippedVocabulary(name);
    size_t self = 0;
    for (WordId w = 0; w < v->wordCount(); ++w) self += v->quantize(v->centre(v->data().node_of_word[w])) == w;
    const double fraction = double(self) / v->wordCount();
    RecordProperty(std::string(name) + "_self_fraction", std::to_string(fraction));
    EXPECT_GE(fraction, required) << name << ": " << self << " of " << v->wordCount();
    std::printf("%s: %zu of %zu word centres land in their own word\n", name, self, v->wordCount());
  }
}

#include "urbanslam/common/IniFile.h"
#include "urbanslam/vision_loop/ImageLoopOptions.h"

TEST(ImageLoopOptions, IniKeysReachTheDetector) {
  urbanslam::common::OptionsSchema schema;
  ImageLoopOptions o;
  schema.section("image_loop", "Tree of Words");
  declareImageLoopOptions(schema, o);
  schema.load(
      urbanslam::common::IniFile::parse("[image_loop]\nmin_normalized_score = 0.5\nmin_inliers = 15\nmax_features = 300\n", "test.ini"));
  const LoopDetectorOptions d = detectorOptions(o);
  EXPECT_FLOAT_EQ(d.min_normalized_score, 0.5f);
  EXPECT_EQ(d.verification.min_inliers, 15);
  EXPECT_EQ(featureOptions(o, DescriptorType::Orb).max_features, 300);
  EXPECT_THROW(schema.load(urbanslam::common::IniFile::parse("[image_loop]\nmin_inlier = 3\n", "bad.ini")), urbanslam::common::ConfigError);
}
