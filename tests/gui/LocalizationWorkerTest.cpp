// The GUI's localization mode without wx: a map of the Intel excerpt saved as map.usmap, the
// same log localized in it by the worker, against the library's batch localization (what
// `urbanslam localize` runs) on the same map and log.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "TestPaths.h"
#include "WaitFor.h"
#include "model/DrawList.h"
#include "model/LocalizationWorker.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/MapFile.h"

using namespace urbanslam;
using namespace std::chrono_literals;
using test::waitFor;

namespace {
const std::string kLog = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");


// The excerpt mapped with the default options and saved as DIR/map.usmap; its path. (ctest runs
// the tests in parallel: each passes a folder of its own.)
std::string excerptMap(const std::filesystem::path& dir) {
  const std::string path = (dir / "map.usmap").string();
  slam::Pipeline p(slam::PipelineOptions{});
  auto src = io::openDataSource(kLog);
  while (p.step(*src)) {
  }
  p.waitForGlobalSlam(*src);
  slam::saveMap(p, path);
  return path;
}
}  // namespace

TEST(LocalizationWorker, LocalizesLikeTheBatchLocalizerAndDrawsTheMapAndThePath) {
  const std::string map = excerptMap(test::scratchDir("gui_localization_map"));
  // The reference: the library's own run over the same map and log.
  std::unique_ptr<slam::Pipeline> loaded = slam::loadMap(map);
  loaded->finish();
  slam::Localizer batch(loaded->map(), loaded->options(), slam::localizerOptions(loaded->options()));
  auto src = io::openDataSource(kLog);
  const auto expected = slam::localizeInMaps({&batch}, *src, {}, &loaded->options()).scans;
  ASSERT_GT(expected.size(), 50u);
  size_t expected_poses = 0, expected_lost = 0;
  for (const auto& r : expected) {
    expected_poses += r.has_pose;
    expected_lost += r.state == slam::LocalizationState::Lost;
  }

  gui::LocalizationWorker w(map, kLog);
  const gui::MapSnapshot before = w.snapshot();
  EXPECT_TRUE(before.localizing);
  EXPECT_EQ(before.keyframes.size(), loaded->keyframes().size());  // the map, drawn before anything runs
  EXPECT_TRUE(before.localized.empty());
  w.stepScan();
  ASSERT_TRUE(waitFor([&] { return w.snapshot().stats.scans == 1; }, 60s));
  w.play();
  ASSERT_TRUE(waitFor([&] { return w.finished(); }, 120s));  // sanitizer builds are slow
  EXPECT_EQ(w.error(), "");
  const gui::MapSnapshot s = w.snapshot();
  EXPECT_TRUE(s.finished);
  EXPECT_EQ(s.stats.scans, expected.size());
  EXPECT_EQ(s.localized.size(), expected_poses);
  EXPECT_EQ(s.lost_scans, expected_lost);
  ASSERT_FALSE(s.localized.empty());
  const auto& last = expected.back();
  EXPECT_NEAR(s.localized.back().pose.x, last.pose.x, 1e-9);
  EXPECT_NEAR(s.localized.back().pose.y, last.pose.y, 1e-9);

  // The map's keyframes stay as saved; the path is drawn by state, the vehicle at its end.
  const gui::DrawList d = gui::buildDrawList(s, {});
  EXPECT_EQ(d.keyframes_drawn, loaded->keyframes().size());
  EXPECT_GT(d.map_points.size(), 1000u);
  EXPECT_EQ(d.localized_tracked.size() + d.localized_lost.size(), s.localized.size() - 1);
  EXPECT_GT(d.localized_tracked.size(), d.localized_lost.size());  // the log localized in its own map
  ASSERT_TRUE(d.current_pose.has_value());
  EXPECT_EQ(d.current_pose->x, s.localized.back().pose.x);
  EXPECT_TRUE(d.uncertainty.has_value());
}

TEST(LocalizationWorker, BadInputGivesTheCliMessage) {
  const auto d = test::scratchDir("gui_localization_bad");
  const std::string not_a_map = (d / "not_a_map.usmap").string();
  std::ofstream(not_a_map) << "not a map";
  EXPECT_THROW(gui::LocalizationWorker(not_a_map, kLog), common::InputError);
  EXPECT_THROW(gui::LocalizationWorker(excerptMap(d), (d / "missing.rawlog").string()), common::InputError);
}

// A file of two maps, the FR079 excerpt's first and the Intel excerpt's as a separate map (both
// with FR079's ini, as one file's maps share their options): the Intel log is found in its own
// map, which is drawn from then on, and the poses drawn are those the Intel map's localizer gives
// alone from the scan at which it found its place.
TEST(LocalizationWorker, SearchesEveryMapOfTheFileAndDrawsTheOneThatHoldsTheLog) {
  const auto dir = test::scratchDir("gui_localization_maps");
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  const auto mapOf = [&](const std::string& log, size_t scans) {
    auto p = std::make_unique<slam::Pipeline>(o);
    auto src = io::openDataSource(log);
    while (p->stats().scans < scans && p->step(*src)) {
    }
    p->waitForGlobalSlam(*src);
    return p;
  };
  const auto fr079 = mapOf(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), 300), intel = mapOf(kLog, 100000);
  const std::string file = (dir / "map.usmap").string();
  slam::saveMap(*fr079, file, {intel.get()});

  // The reference: the Intel map's localizer alone, on the map as saved and loaded.
  std::vector<std::unique_ptr<slam::Pipeline>> separate;
  auto loaded = slam::loadMap(file, nullptr, &separate);
  ASSERT_EQ(separate.size(), 1u);
  separate[0]->finish();
  slam::Localizer alone(separate[0]->map(), separate[0]->options(), slam::localizerOptions(separate[0]->options()));
  auto src = io::openDataSource(kLog);
  const auto expected = slam::localizeInMaps({&alone}, *src, {}, &separate[0]->options()).scans;
  size_t found = 0;
  while (found < expected.size() && expected[found].state != slam::LocalizationState::Tracking) ++found;
  ASSERT_LT(found, expected.size() / 2);
  size_t expected_poses = 0;
  for (size_t i = found; i < expected.size(); ++i) expected_poses += expected[i].has_pose;

  gui::LocalizationWorker w(file, kLog);
  EXPECT_EQ(w.snapshot().keyframes.size(), fr079->keyframes().size());  // the first map until the log is found
  w.play();
  ASSERT_TRUE(waitFor([&] { return w.finished(); }, 240s));
  EXPECT_EQ(w.error(), "");
  const gui::MapSnapshot s = w.snapshot();
  EXPECT_EQ(s.keyframes.size(), intel->keyframes().size());
  EXPECT_EQ(s.stats.scans, expected.size());
  ASSERT_EQ(s.localized.size(), expected_poses);
  ASSERT_FALSE(s.localized.empty());
  EXPECT_NEAR(s.localized.front().pose.x, expected[found].pose.x, 1e-9);
  EXPECT_NEAR(s.localized.back().pose.x, expected.back().pose.x, 1e-9);
  EXPECT_NEAR(s.localized.back().pose.y, expected.back().pose.y, 1e-9);
}
