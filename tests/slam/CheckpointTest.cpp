// A run killed after a checkpoint and continued from it ends as the uninterrupted run over the
// same log ends (the reference): the same keyframes, poses and closures. A checkpoint that does
// not fit its input or is damaged is refused with an error naming it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/slam/Checkpoint.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;
namespace fs = std::filesystem;

namespace {

constexpr const char* kLog = "rawlogs/fr079-raw-excerpt.clf.gz";

slam::PipelineOptions fr079Options() {
  slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  slam::resolveDefaultPaths(o, URBANSLAM_SOURCE_DIR);
  return o;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A run with a checkpoint every `every` keyframes that stops (as if killed) `lost` measurements
// after its `stop_after`-th checkpoint, without finishing or saving anything else.
void runUntilKilled(const slam::PipelineOptions& o, const std::string& dir, size_t every, size_t stop_after, size_t lost,
                    uint64_t* measurements_at_checkpoint) {
  slam::Pipeline p(o);
  auto src = io::openDataSource(test::repoPath(kLog));
  slam::CheckpointInfo start;
  start.input = kLog;
  slam::Checkpointer saver(dir, every, start, 0);
  saver.setCounters([&] { return std::map<std::string, double>{{"keyframes_seen", static_cast<double>(p.keyframesMade())}}; });
  while (p.step(*src)) {
    if (saver.afterStep(p, *src) && saver.saved() == stop_after) break;
  }
  ASSERT_EQ(saver.saved(), stop_after) << "the log is too short for the checkpoints asked for";
  *measurements_at_checkpoint = p.stats().measurements;
  for (size_t i = 0; i < lost; ++i) ASSERT_TRUE(p.step(*src));  // work the kill loses
}

}  // namespace

TEST(Checkpoint, AContinuedRunEndsAsTheUninterruptedOne) {
  const slam::PipelineOptions o = fr079Options();
  slam::Pipeline whole(o);
  {
    auto src = io::openDataSource(test::repoPath(kLog));
    whole.run(*src);
  }
  const std::string dir = (test::scratchDir("checkpoint_continue") / "run.checkpoint").string();
  uint64_t at_checkpoint = 0;
  runUntilKilled(o, dir, 60, 2, 150, &at_checkpoint);

  slam::Checkpoint c = slam::loadCheckpoint(dir, &o);
  EXPECT_EQ(c.info.input, kLog);
  EXPECT_EQ(c.info.input_measurements, at_checkpoint);
  EXPECT_EQ(c.pipeline->stats().measurements, at_checkpoint);
  EXPECT_GE(c.info.keyframes, 120u);
  EXPECT_EQ(c.pipeline->keyframes().size(), c.info.keyframes);
  EXPECT_EQ(c.info.counters.at("keyframes_seen"), static_cast<double>(c.info.keyframes));
  EXPECT_GT(c.info.cpu_s, 0.0);
  EXPECT_GT(c.info.wall_s, 0.0);
  ASSERT_LT(c.info.keyframes, whole.keyframes().size() / 2) << "the continued part is worth testing only when it maps most of the log";

  // Continued with checkpoints of its own: the times go on from the earlier stretch.
  auto src = io::openDataSource(test::repoPath(kLog));
  slam::skipMeasurements(*src, c.info.input_measurements, kLog);
  slam::Checkpointer saver(dir, 60, c.info, 0);
  slam::runCheckpointed(*c.pipeline, *src, saver);
  EXPECT_GT(saver.saved(), 0u);
  EXPECT_GT(saver.cpuSeconds(), c.info.cpu_s);
  const slam::CheckpointInfo last = slam::loadCheckpoint(dir, &o).info;  // the continued run's latest
  EXPECT_GT(last.keyframes, c.info.keyframes);
  EXPECT_GT(last.cpu_s, c.info.cpu_s);
  EXPECT_EQ(last.input, kLog);
  c.pipeline->finish(*src);

  const slam::Pipeline& cont = *c.pipeline;
  ASSERT_EQ(whole.keyframes().size(), cont.keyframes().size());
  for (size_t i = 0; i < whole.keyframes().size(); ++i) {
    const auto &a = whole.keyframes()[i], &b = cont.keyframes()[i];
    ASSERT_EQ(a.timestamp, b.timestamp) << i;
    EXPECT_NEAR(a.pose.x, b.pose.x, 1e-9) << i;
    EXPECT_NEAR(a.pose.y, b.pose.y, 1e-9) << i;
    EXPECT_NEAR(a.pose.phi, b.pose.phi, 1e-9) << i;
  }
  const auto ca = whole.loopClosures(), cb = cont.loopClosures();
  ASSERT_EQ(ca.size(), cb.size());
  size_t accepted_after = 0;
  for (size_t i = 0; i < ca.size(); ++i) {
    EXPECT_EQ(ca[i].from, cb[i].from) << i;
    EXPECT_EQ(ca[i].to, cb[i].to) << i;
    EXPECT_EQ(ca[i].accepted, cb[i].accepted) << i;
    accepted_after += ca[i].accepted && ca[i].to >= c.info.keyframes ? 1 : 0;
  }
  EXPECT_GT(accepted_after, 0u) << "no closure after the checkpoint: the test would not see one lost";
  EXPECT_EQ(whole.stats().measurements, cont.stats().measurements);
}

TEST(Checkpoint, OneThatDoesNotFitItsInputIsRefusedNamingIt) {
  const slam::PipelineOptions o = fr079Options();
  const fs::path scratch = test::scratchDir("checkpoint_refused");
  const std::string dir = (scratch / "run.checkpoint").string();
  uint64_t at_checkpoint = 0;
  runUntilKilled(o, dir, 40, 1, 0, &at_checkpoint);

  // An input shorter than what the checkpoint read: not the input it was made from.
  auto src = io::openDataSource(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"));
  try {
    slam::skipMeasurements(*src, 100000000, "short.clf");
    FAIL() << "skipped past the end";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("short.clf"), std::string::npos) << e.what();
  }

  // A missing folder, a folder without its info, an info that does not describe the map, a
  // damaged map: each an InputError naming the folder or file.
  const auto refused = [&](const std::string& d, const std::string& named) {
    try {
      slam::loadCheckpoint(d, &o);
      ADD_FAILURE() << d << " was loaded";
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  refused((scratch / "none").string(), "none");
  const fs::path copy = scratch / "copy.checkpoint";
  fs::copy(dir, copy);
  const std::string info = slurp(copy / "checkpoint.ini");
  const auto set = [&](const std::string& text) { std::ofstream(copy / "checkpoint.ini") << text; };
  const size_t kf = info.find("keyframes = ");
  ASSERT_NE(kf, std::string::npos);
  set(info.substr(0, kf) + "keyframes = 1\n" + info.substr(info.find('\n', kf) + 1));
  refused(copy.string(), copy.string());
  set(info.substr(0, kf) + info.substr(info.find('\n', kf) + 1));  // the key missing
  refused(copy.string(), "keyframes");
  set(info);
  std::string map = slurp(copy / "map.usmap");
  map[map.size() / 2] = static_cast<char>(map[map.size() / 2] ^ 0x20);
  std::ofstream(copy / "map.usmap", std::ios::binary) << map;
  refused(copy.string(), "map.usmap");
  fs::remove(copy / "checkpoint.ini");
  refused(copy.string(), "checkpoint.ini");
}
