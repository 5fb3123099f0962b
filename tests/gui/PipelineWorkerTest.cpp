#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "TestPaths.h"
#include "WaitFor.h"
#include "model/PipelineWorker.h"
#include "urbanslam/common/Error.h"

using namespace urbanslam;
using namespace std::chrono_literals;
using test::waitFor;

namespace {
const std::string kLog = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
const std::string kIni = test::repoPath("ini/default.ini");
// The project home, whose shipped classifiers the ini leaves to the default (the GUI's home).
const std::string kHome = test::repoPath("");

}  // namespace

TEST(PipelineWorker, StartsPausedAndStepsOneKeyframeAtATime) {
  gui::PipelineWorker w(kLog, kIni, kHome);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(w.collector().snapshot().keyframes.size(), 0u);  // nothing runs before play/step
  for (size_t k = 1; k <= 3; ++k) {
    w.stepKeyframe();
    ASSERT_TRUE(waitFor([&] { return !w.running(); }));
    EXPECT_EQ(w.collector().snapshot().keyframes.size(), k);
  }
}

TEST(PipelineWorker, PlayRunsToTheEndLikeTheBatchPipeline) {
  gui::PipelineWorker w(kLog, kIni, kHome);
  w.play();
  ASSERT_TRUE(waitFor([&] { return w.finished(); }));
  const auto snap = w.collector().snapshot();
  EXPECT_TRUE(snap.finished);
  EXPECT_EQ(w.error(), "");
  // Same keyframes as a batch run of the same input and ini.
  slam::PipelineOptions options = slam::loadPipelineOptions(kIni);
  slam::resolveDefaultPaths(options, test::repoPath(""));
  slam::Pipeline batch(options);
  auto src = io::openDataSource(kLog);
  batch.run(*src);
  ASSERT_EQ(snap.keyframes.size(), batch.keyframes().size());
  for (size_t i = 0; i < snap.keyframes.size(); ++i) EXPECT_EQ(snap.keyframes[i].pose.x, batch.keyframes()[i].pose.x);
  size_t n = 0;
  w.withPipeline([&](const slam::Pipeline& p) { n = p.keyframes().size(); });
  EXPECT_EQ(n, batch.keyframes().size());
}

TEST(PipelineWorker, PauseStopsProgress) {
  gui::PipelineWorker w(kLog, kIni, kHome);
  w.setSpeed(50);  // 50x real time: the 270 s excerpt takes seconds, long enough to pause
  w.play();
  ASSERT_TRUE(waitFor([&] { return w.collector().snapshot().keyframes.size() >= 2; }));
  w.pause();
  std::this_thread::sleep_for(700ms);  // let a paced sleep in flight end
  const size_t a = w.collector().snapshot().keyframes.size();
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(w.collector().snapshot().keyframes.size(), a);
  EXPECT_FALSE(w.finished());
}

TEST(PipelineWorker, BadInputGivesTheCliMessage) {
  try {
    gui::PipelineWorker w("/nonexistent.rawlog", kIni);
    FAIL() << "no error";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent.rawlog: no such file"), std::string::npos);
  }
  EXPECT_THROW(gui::PipelineWorker(kLog, "/nonexistent.ini"), common::InputError);
}
