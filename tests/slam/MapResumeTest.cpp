// A run saved to a map file and continued by another run over the rest of the log ends exactly
// where one uninterrupted run over the whole log ends: the uninterrupted run is the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "MapFileSections.h"
#include "SkippingSource.h"
#include "TestPaths.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

struct Case {
  std::string log, ini;
  size_t split;                   // measurements in the first run
  bool laser_classifier = false;  // [loop_closure] detector = laser (its features come back from the scans)
};

// Runs to the end of the log, keeping the map file's bytes of the state before finish().
std::unique_ptr<slam::Pipeline> runToEnd(std::unique_ptr<slam::Pipeline> p, io::DataSource& src, std::string* map_bytes) {
  p->runInput(src);
  *map_bytes = slam::encodeMap(*p);
  p->finish(src);
  return p;
}

std::unique_ptr<slam::Pipeline> runWhole(const Case& c, const slam::PipelineOptions& o, std::string* map_bytes) {
  auto src = io::openDataSource(test::repoPath(c.log));
  return runToEnd(std::make_unique<slam::Pipeline>(o), *src, map_bytes);
}

// The first `split` measurements, saved to `map`; then a fresh pipeline from the map over the
// log after them. `split_time`: the time of the last measurement before the split.
std::unique_ptr<slam::Pipeline> runSplit(const Case& c, const slam::PipelineOptions& o, const std::string& map, double* split_time,
                                         std::string* map_bytes) {
  {
    slam::Pipeline first(o);
    auto src = io::openDataSource(test::repoPath(c.log));
    for (size_t i = 0; i < c.split; ++i) EXPECT_TRUE(first.step(*src));
    *split_time = first.stats().last_timestamp;
    slam::saveMap(first, map);
  }
  test::SkippingSource rest(io::openDataSource(test::repoPath(c.log)), c.split);
  return runToEnd(slam::loadMap(map, &o), rest, map_bytes);
}

void expectSamePoses(const std::vector<io::StampedPose>& a, const std::vector<io::StampedPose>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].timestamp, b[i].timestamp) << what << " " << i;
    EXPECT_NEAR(a[i].pose.x, b[i].pose.x, 1e-6) << what << " " << i;
    EXPECT_NEAR(a[i].pose.y, b[i].pose.y, 1e-6) << what << " " << i;
    EXPECT_NEAR(a[i].pose.phi, b[i].pose.phi, 1e-6) << what << " " << i;
  }
}

void expectResumeEqualsWholeRun(const Case& c) {
  slam::PipelineOptions o = slam::loadPipelineOptions(c.ini.empty() ? "" : test::repoPath(c.ini));
  o.loop_closure.detector = c.laser_classifier ? slam::LoopClosureOptions::Detector::Laser : slam::LoopClosureOptions::Detector::None;
  slam::resolveDefaultPaths(o, URBANSLAM_SOURCE_DIR);
  std::string whole_map, resumed_map;
  const auto whole = runWhole(c, o, &whole_map);
  double split_time = 0;
  // One folder per test: ctest runs the cases in parallel, and each clears its folder.
  const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const auto map_path = test::scratchDir("map_resume_" + test_name) / "map.usmap";
  const auto resumed = runSplit(c, o, map_path.string(), &split_time, &resumed_map);

  // The split is worth testing only when the second part closes loops of its own.
  ASSERT_LT(c.split, whole->stats().measurements);
  size_t closures_after = 0;
  for (const auto& r : whole->loopClosures()) closures_after += r.accepted && r.to_time > split_time ? 1 : 0;
  EXPECT_GT(closures_after, 0u);

  ASSERT_EQ(whole->keyframes().size(), resumed->keyframes().size());
  const auto whole_closures = whole->loopClosures(), resumed_closures = resumed->loopClosures();
  ASSERT_EQ(whole_closures.size(), resumed_closures.size());
  for (size_t i = 0; i < whole_closures.size(); ++i) {
    const auto &a = whole_closures[i], &b = resumed_closures[i];
    EXPECT_EQ(a.from, b.from) << i;
    EXPECT_EQ(a.to, b.to) << i;
    EXPECT_EQ(a.accepted, b.accepted) << i;
    EXPECT_EQ(slam::reasonName(a.reason), std::string(slam::reasonName(b.reason))) << i;
  }
  for (size_t i = 0; i < whole->keyframes().size(); ++i) {
    const auto &a = whole->keyframes()[i], &b = resumed->keyframes()[i];
    EXPECT_EQ(a.timestamp, b.timestamp) << i;
    EXPECT_NEAR(a.pose.x, b.pose.x, 1e-6) << i;
    EXPECT_NEAR(a.pose.y, b.pose.y, 1e-6) << i;
    EXPECT_NEAR(a.pose.phi, b.pose.phi, 1e-6) << i;
  }
  expectSamePoses(whole->odometryTrajectory(), resumed->odometryTrajectory(), "odometry trajectory");
  expectSamePoses(whole->scanTrajectory(), resumed->scanTrajectory(), "scan trajectory");
  EXPECT_EQ(whole->graphEdges().size(), resumed->graphEdges().size());
  EXPECT_EQ(whole->stats().measurements, resumed->stats().measurements);
  EXPECT_EQ(whole->stats().scans_anchored, resumed->stats().scans_anchored);
  EXPECT_EQ(whole->stats().closures_tried, resumed->stats().closures_tried);

  // Beyond the results, the whole state at the end of the log is the same, byte for byte: the
  // map, the filter (down to its last factorisation), local and global SLAM. Only the statistics
  // differ (they hold processing times).
  const auto a = test::mapFileSections(whole_map), b = test::mapFileSections(resumed_map);
  EXPECT_EQ(a.size(), 8u);
  for (const char* tag : {"OPTS", "MAP ", "ESDF", "LOCL", "GLOB", "IMGS", "SEPM"}) {
    ASSERT_TRUE(a.count(tag) && b.count(tag)) << tag;
    EXPECT_TRUE(a.at(tag) == b.at(tag)) << "section " << tag << " differs";
  }
}

}  // namespace

// The shipped Intel rawlog (default options), split in the middle: 407 closures in all, many
// after the split.
TEST(MapResume, IntelSplitInTheMiddleEqualsTheWholeRun) { expectResumeEqualsWholeRun({"rawlogs/intel.rawlog", "", 7700}); }

// The Freiburg 079 excerpt with its ini (front laser only, scans matched between keyframes).
TEST(MapResume, Fr079ExcerptSplitEqualsTheWholeRun) {
  expectResumeEqualsWholeRun({"rawlogs/fr079-raw-excerpt.clf.gz", "ini/fr079.ini", 2000});
}

// The same with the laser classifier screening the candidates: its keyframe features are not in
// the file but recomputed from the keyframes' scans.
TEST(MapResume, Fr079ExcerptWithTheLaserClassifierEqualsTheWholeRun) {
  expectResumeEqualsWholeRun({"rawlogs/fr079-raw-excerpt.clf.gz", "ini/fr079.ini", 2600, true});
}
