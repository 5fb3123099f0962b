// The camera panel's model: on the RTAB-Map excerpt with Tree of Words, a proposal puts the
// current keyframe's frame and the matched earlier frame side by side, and snapshots share the
// image buffers instead of copying them.
#include <gtest/gtest.h>

#include <filesystem>

#include "TestPaths.h"
#include "model/CameraView.h"
#include "model/SnapshotCollector.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;
namespace fs = std::filesystem;

namespace {

gui::MapSnapshot runExcerpt(slam::LoopClosureOptions::ImageDetector image_detector,
                            std::vector<slam::LoopClosureRecord>* records = nullptr) {
  slam::PipelineOptions o;
  o.loop_closure.image_detector = image_detector;
  o.image_loop.vocabulary = test::repoPath("share/vision_loop/sift_k10_L4.usvoc");
  gui::SnapshotCollector c;  // outlives the pipeline
  slam::Pipeline p(o);
  p.addObserver(&c);
  auto src = io::openDataSource(test::repoPath("rawlogs/rtabmap-loop-excerpt"));
  p.run(*src);
  if (records) *records = p.loopClosures();
  return c.snapshot();
}

std::string fileOf(const gui::CameraFrame& f) { return f.image ? fs::path(f.image->source).filename().string() : ""; }

}  // namespace

TEST(CameraView, ShowsTheMatchedFrameOfAProposal) {
  std::vector<slam::LoopClosureRecord> records;
  const gui::MapSnapshot s = runExcerpt(slam::LoopClosureOptions::ImageDetector::TreeOfWords, &records);
  ASSERT_FALSE(s.image_matches.empty());
  // Every proposal the pipeline recorded is in the model, with its fate.
  size_t image_records = 0;
  for (const auto& r : records) image_records += r.detector == slam::Proposer::Image;
  EXPECT_EQ(s.image_matches.size(), image_records);
  for (const auto& m : s.image_matches) {
    // Clicking the proposing keyframe: its frame left, the matched earlier frame right. The
    // reference is the file each keyframe's image came from (the n-th image of the folder).
    const gui::CameraView v = gui::cameraView(s, m.current);
    ASSERT_TRUE(v.match.has_value());
    EXPECT_EQ(v.current.keyframe, m.current);
    EXPECT_EQ(v.matched.keyframe, m.matched);
    ASSERT_TRUE(v.current.image && v.matched.image);
    EXPECT_EQ(fileOf(v.current), fs::path(s.keyframes[m.current].image->source).filename().string());
    EXPECT_NE(fileOf(v.current), fileOf(v.matched));
    EXPECT_EQ(v.match->fate, "no_scans");  // camera only: a proposal on record
    EXPECT_NE(v.match_caption.find("no_scans"), std::string::npos);
  }
  // The running view (nothing clicked) at the end of the run: the newest keyframe's frame, and
  // the newest proposal beside it while it is recent.
  const gui::CameraView live = gui::cameraView(s);
  ASSERT_TRUE(live.current.image);
  const auto& last = s.image_matches.back();
  if (s.keyframes.size() - 1 - last.current <= gui::kMatchHoldKeyframes) {
    EXPECT_EQ(live.matched.keyframe, last.matched);
    EXPECT_EQ(live.current.keyframe, last.current);
  } else {
    EXPECT_FALSE(live.match.has_value());
  }
}

TEST(CameraView, WithoutTheDetectorFramesButNoMatch) {
  const gui::MapSnapshot s = runExcerpt(slam::LoopClosureOptions::ImageDetector::None);
  ASSERT_EQ(s.keyframes.size(), 32u);
  EXPECT_TRUE(s.image_matches.empty());
  const gui::CameraView v = gui::cameraView(s, 5);
  ASSERT_TRUE(v.current.image);
  EXPECT_FALSE(v.matched.image);
  EXPECT_FALSE(v.match.has_value());
}

// A snapshot copies pointers to the images, not the pixels.
TEST(CameraView, SnapshotsShareImageBuffers) {
  slam::PipelineOptions o;  // the default pipeline: Tree of Words on, with the shipped vocabulary
  o.image_loop.vocabulary = test::repoPath("share/vision_loop/sift_k10_L4.usvoc");
  gui::SnapshotCollector c;  // outlives the pipeline
  slam::Pipeline p(o);
  p.addObserver(&c);
  auto src = io::openDataSource(test::repoPath("rawlogs/rtabmap-loop-excerpt"));
  for (int i = 0; i < 4; ++i) p.step(*src);
  p.waitForGlobalSlam(*src);  // the keyframes' images are attached by global SLAM
  const gui::MapSnapshot a = c.snapshot(), b = c.snapshot();
  ASSERT_GE(a.keyframes.size(), 3u);
  for (size_t i = 0; i < a.keyframes.size(); ++i) {
    ASSERT_TRUE(a.keyframes[i].image);
    EXPECT_EQ(a.keyframes[i].image->pixels.get(), b.keyframes[i].image->pixels.get());
  }
  // The keyframe image and the latest camera frame are the reader's buffer too.
  EXPECT_EQ(a.keyframes.back().image->pixels.get(), a.last_image->pixels.get());
}
