// The camera's places in a frozen map, against the map's own images: a keyframe's image, seen
// again, has the same words (the map's vocabulary and feature settings) and comes first with
// similarity 1; an image too old for the scan, or from before the asked time, is not used.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "TestPaths.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/ImagePlaces.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

using namespace urbanslam;

namespace {

io::CameraImage excerptImage(int k, double timestamp) {
  const cv::Mat gray = cv::imread(test::repoPath("rawlogs/rtabmap-loop-excerpt/" + std::to_string(k) + ".jpg"), cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(gray.empty()) << k;
  io::CameraImage im;
  im.timestamp = timestamp;
  im.width = gray.cols;
  im.height = gray.rows;
  im.pixels = std::make_shared<const std::vector<uint8_t>>(gray.datastart, gray.dataend);
  return im;
}

}  // namespace

TEST(ImagePlaces, AKeyframesImageSeenAgainIsFoundFirstWhileItIsFresh) {
  slam::ImagePlaceOptions o;
  o.image_loop.vocabulary = test::repoPath("share/vision_loop/orb_k10_L4.usvoc");
  const vision_loop::Vocabulary vocabulary = vision_loop::loadVocabulary(o.image_loop.vocabulary);
  const vision_loop::FeatureExtractor extractor(vision_loop::featureOptions(o.image_loop, vocabulary.descriptorType()));
  // Keyframes 0..15, every other one with an image of the excerpt (1.jpg, 3.jpg, ...) as a run
  // keeps it: its words only.
  slam::Map map(nullptr, 1.0);
  for (size_t k = 0; k < 16; ++k) {
    slam::Keyframe kf;
    kf.index = k;
    kf.timestamp = static_cast<double>(k);
    kf.pose = {static_cast<double>(k), 0.0, 0.0};
    if (k % 2 == 0) {
      const io::CameraImage im = excerptImage(static_cast<int>(k) + 1, kf.timestamp);
      const cv::Mat gray(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data()));
      kf.has_image = true;
      kf.image_words = vocabulary.transform(extractor.extract(gray).descriptors);
    }
    map.addKeyframe(kf, io::CompactScan{});
  }
  slam::ImagePlaces places(map, o);
  ASSERT_TRUE(places.mapHasImages());
  EXPECT_TRUE(places.query(100.0).empty());  // no image yet

  places.addImage(excerptImage(7, 100.0));  // keyframe 6's image
  const std::vector<slam::ImagePlace> found = places.query(100.3);
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found.front().keyframe, 6u);
  EXPECT_NEAR(found.front().score, 1.0, 1e-5);
  EXPECT_LE(found.size(), o.max_places);
  for (size_t i = 1; i < found.size(); ++i) {
    EXPECT_LT(found[i].score, found.front().score);
    EXPECT_EQ(found[i].keyframe % 2, 0u);  // only keyframes with an image
  }
  EXPECT_TRUE(places.query(100.0 + o.max_age_s + 0.1).empty());  // too old for the scan
  EXPECT_TRUE(places.query(100.3, 100.2).empty());               // taken before the asked time
  EXPECT_EQ(places.queries(), 1u);

  // Without image words in the map, or with the option off, images are not even kept.
  slam::Map bare(nullptr, 1.0);
  slam::Keyframe kf;
  bare.addKeyframe(kf, io::CompactScan{});
  slam::ImagePlaces none(bare, o);
  EXPECT_FALSE(none.mapHasImages());
  none.addImage(excerptImage(7, 100.0));
  EXPECT_TRUE(none.query(100.3).empty());
  o.enabled = false;
  EXPECT_FALSE(slam::ImagePlaces(map, o).mapHasImages());
}
