// Localization in several maps side by side, checked against the single localizer of the map
// that holds the log (a run of its own): the Intel excerpt is found in its own map and not in the
// FR079 excerpt's, whichever is listed first, and the chosen map's results are the ones its
// localizer gives alone.
#include <gtest/gtest.h>

#include <memory>

#include "TestPaths.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

std::string intel() { return test::repoPath("rawlogs/intel-corrected-excerpt.log.gz"); }

// The map of a log's first `scans` scans, with the ini of FR079 (both excerpts map with it).
std::unique_ptr<slam::Pipeline> mapOf(const std::string& log, size_t scans) {
  auto p = std::make_unique<slam::Pipeline>(slam::loadPipelineOptions(test::repoPath("ini/fr079.ini")));
  auto src = io::openDataSource(log);
  while (p->stats().scans < scans && p->step(*src)) {
  }
  p->finish();
  return p;
}

std::unique_ptr<slam::Localizer> localizerIn(const slam::Pipeline& map) {
  return std::make_unique<slam::Localizer>(map.map(), map.options(), slam::localizerOptions(map.options()));
}

}  // namespace

TEST(LocalizeInMaps, GoesOnInTheMapThatHoldsTheLogWhereverItIsListed) {
  const auto intel_map = mapOf(intel(), 100000);
  const auto fr079_map = mapOf(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), 300);

  // Alone in the Intel map: the reference.
  auto alone = localizerIn(*intel_map);
  auto alone_src = io::openDataSource(intel());
  const slam::MapsLocalization reference = slam::localizeInMaps({alone.get()}, *alone_src);
  ASSERT_EQ(reference.map, 0u);
  size_t tracked = 0;
  for (const auto& s : reference.scans) tracked += s.state == slam::LocalizationState::Tracking;
  ASSERT_GT(tracked, reference.scans.size() / 2);

  for (const bool intel_first : {false, true}) {
    auto a = localizerIn(*fr079_map), b = localizerIn(*intel_map);
    std::vector<slam::Localizer*> both =
        intel_first ? std::vector<slam::Localizer*>{b.get(), a.get()} : std::vector<slam::Localizer*>{a.get(), b.get()};
    auto src = io::openDataSource(intel());
    size_t reported = 0;
    const slam::MapsLocalization r = slam::localizeInMaps(both, *src, [&](const slam::LocalizedScan&, double) { ++reported; });
    EXPECT_EQ(r.map, intel_first ? 0u : 1u);
    ASSERT_EQ(r.scans.size(), reference.scans.size());
    for (size_t i = 0; i < r.scans.size(); ++i) {
      EXPECT_EQ(r.scans[i].state, reference.scans[i].state) << i;
      EXPECT_EQ(r.scans[i].timestamp, reference.scans[i].timestamp) << i;
      EXPECT_EQ(r.scans[i].pose.x, reference.scans[i].pose.x) << i;
      EXPECT_EQ(r.scans[i].pose.y, reference.scans[i].pose.y) << i;
    }
    EXPECT_GE(reported, r.scans.size());
    // The FR079 map does not hold the log: its localizer found nothing while both ran.
    EXPECT_EQ(a->stats().relocalisations, 0u);
  }
}
