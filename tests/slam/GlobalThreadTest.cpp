// Global SLAM on a thread of its own gives the same map as global SLAM inline: local SLAM never
// reads global SLAM's estimates, and global SLAM takes the keyframes in order. The inline run
// is the reference.
#include <gtest/gtest.h>

#include <mutex>

#include "MapFileSections.h"
#include "TestPaths.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

// Counts what global SLAM reports, from whichever thread it runs on.
struct Recorder : slam::PipelineObserver {
  void onKeyframe(const slam::KeyframeEvent& e) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (e.index != keyframes) out_of_order = true;
    ++keyframes;
  }
  void onPosesUpdated(const slam::PosesUpdatedEvent& e) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (e.keyframe != static_cast<size_t>(-1)) {
      // Corrections land in the order of the closures that brought them.
      if (corrections > 0 && e.keyframe <= last_corrected) out_of_order = true;
      last_corrected = e.keyframe;
      ++corrections;
    }
  }
  std::mutex mutex;
  size_t keyframes = 0, corrections = 0, last_corrected = 0;
  bool out_of_order = false;
};

struct PipelineRun {
  Recorder recorder;  // outlives the pipeline, whose global SLAM thread calls it
  std::unique_ptr<slam::Pipeline> pipeline;
  std::string state;  // the map file's bytes before finish()
};

void run(const std::string& log, bool threaded, PipelineRun& r) {
  slam::PipelineOptions o = slam::loadPipelineOptions("");
  o.estimator.global_thread = threaded;
  r.pipeline = std::make_unique<slam::Pipeline>(o);
  r.pipeline->addObserver(&r.recorder);
  auto src = io::openDataSource(test::repoPath(log));
  r.pipeline->runInput(*src);
  r.state = slam::encodeMap(*r.pipeline);
  r.pipeline->finish(*src);
}

}  // namespace

TEST(GlobalThread, SameMapAsGlobalSlamInline) {
  PipelineRun inline_run, threaded_run;
  run("rawlogs/intel.rawlog", false, inline_run);
  run("rawlogs/intel.rawlog", true, threaded_run);
  const slam::Pipeline &a = *inline_run.pipeline, &b = *threaded_run.pipeline;

  ASSERT_GT(a.stats().closures_accepted, 100u);  // worth testing: many closures, many recoveries
  ASSERT_EQ(a.keyframes().size(), b.keyframes().size());
  for (size_t i = 0; i < a.keyframes().size(); ++i) {
    EXPECT_EQ(a.keyframes()[i].pose.x, b.keyframes()[i].pose.x) << i;
    EXPECT_EQ(a.keyframes()[i].pose.y, b.keyframes()[i].pose.y) << i;
    EXPECT_EQ(a.keyframes()[i].pose.phi, b.keyframes()[i].pose.phi) << i;
  }
  const auto a_closures = a.loopClosures(), b_closures = b.loopClosures();
  ASSERT_EQ(a_closures.size(), b_closures.size());
  for (size_t i = 0; i < a_closures.size(); ++i) {
    EXPECT_EQ(a_closures[i].from, b_closures[i].from) << i;
    EXPECT_EQ(a_closures[i].to, b_closures[i].to) << i;
    EXPECT_EQ(a_closures[i].accepted, b_closures[i].accepted) << i;
  }
  const auto ta = a.odometryTrajectory(), tb = b.odometryTrajectory();
  ASSERT_EQ(ta.size(), tb.size());
  for (size_t i = 0; i < ta.size(); ++i) EXPECT_EQ(ta[i].pose.x, tb[i].pose.x) << i;
  // The state before finish(), section by section, bar the options (global_thread differs) and
  // the statistics (processing times).
  const auto sa = test::mapFileSections(inline_run.state), sb = test::mapFileSections(threaded_run.state);
  for (const char* tag : {"MAP ", "ESDF", "LOCL", "GLOB", "IMGS"}) {
    ASSERT_TRUE(sa.count(tag) && sb.count(tag)) << tag;
    EXPECT_TRUE(sa.at(tag) == sb.at(tag)) << "section " << tag << " differs";
  }

  // Every keyframe was reported once, in order; a latency for every closure's correction.
  for (const PipelineRun* r : {&inline_run, &threaded_run}) {
    EXPECT_EQ(r->recorder.keyframes, a.keyframes().size());
    EXPECT_FALSE(r->recorder.out_of_order);
    EXPECT_EQ(r->recorder.corrections, r->pipeline->stats().global_latency_ms.count());
    EXPECT_GT(r->recorder.corrections, 0u);
  }
  EXPECT_EQ(inline_run.pipeline->stats().global_backlog_max, 0u);
}
