// Maps that no session links stay separate, each in its own frame, in one map file, until a
// later session joins them. Three sessions cut from the FR079 excerpt: A (scans 0-299) and C
// (700-999) never come within a few metres of each other (checked against the run over the
// whole excerpt); B (200-799) drives through both. The reference is that whole run, whose frame
// is A's (both start at the first scan): once B links them, C's keyframes must lie where it has
// them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>

#include "SkippingSource.h"
#include "TestPaths.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MapMerge.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

std::string excerpt() { return test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"); }
slam::PipelineOptions options() { return slam::loadPipelineOptions(test::repoPath("ini/fr079.ini")); }

constexpr std::array<size_t, 4> kCuts{200, 300, 700, 1000};  // scans

struct Excerpt {
  std::unique_ptr<slam::Pipeline> full;
  std::array<size_t, 4> measurements_at{};  // measurements read when the scan count reached each cut
};

// The whole excerpt in one run, noting where the cuts fall in its measurements.
Excerpt wholeRun() {
  Excerpt e;
  e.full = std::make_unique<slam::Pipeline>(options());
  auto src = io::openDataSource(excerpt());
  size_t next = 0;
  while (e.full->step(*src))
    if (next < kCuts.size() && e.full->stats().scans == kCuts[next]) e.measurements_at[next++] = e.full->stats().measurements;
  e.full->waitForGlobalSlam(*src);
  EXPECT_EQ(next, kCuts.size());
  return e;
}

// The session of the excerpt's scans from the one after `skip_measurements` until it has `scans`.
std::unique_ptr<slam::Pipeline> session(size_t skip_measurements, size_t scans) {
  auto p = std::make_unique<slam::Pipeline>(options());
  test::SkippingSource src(io::openDataSource(excerpt()), skip_measurements);
  while (p->stats().scans < scans && p->step(src)) {
  }
  p->waitForGlobalSlam(src);
  return p;
}

double nearest(const slam::Pipeline& a, const slam::Pipeline& b, double from_t, double to_t) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : a.keyframes())
    for (const auto& q : b.keyframes())
      if (q.timestamp >= from_t && q.timestamp <= to_t) best = std::min(best, std::hypot(p.pose.x - q.pose.x, p.pose.y - q.pose.y));
  return best;
}

}  // namespace

TEST(SeparateMaps, KeptInOneFileUntilASessionLinksThem) {
  const Excerpt e = wholeRun();
  const auto& at = e.measurements_at;
  std::vector<slam::NamedMap> two;
  two.push_back({session(0, kCuts[1]), {"A"}});
  two.push_back({session(at[2], kCuts[3] - kCuts[2]), {"C"}});
  const size_t na = two[0].map->keyframes().size(), nc = two[1].map->keyframes().size();
  const double c_from = two[1].map->keyframes().front().timestamp, c_to = two[1].map->keyframes().back().timestamp;
  // Independent of any join: in the one run, C never comes within 3 m of A.
  ASSERT_GT(nearest(*two[0].map, *e.full, c_from, c_to), 3.0);

  // A and C: nothing links them; C stays separate, and both go into one file.
  slam::MergedMaps apart = slam::mergeMaps(std::move(two));
  ASSERT_EQ(apart.maps.size(), 2u);
  EXPECT_EQ(apart.maps[0].map->keyframes().size(), na);
  EXPECT_EQ(apart.maps[1].sessions, std::vector<std::string>{"C"});
  ASSERT_EQ(apart.sessions.size(), 1u);  // C's search, which found nothing
  EXPECT_EQ(apart.sessions[0].at("name").asString(), "C");
  EXPECT_EQ(apart.sessions[0].at("joined").dump(), "false");
  EXPECT_GT(apart.sessions[0].at("place_searches").asNumber(), 3);
  const std::string path = (test::scratchDir("separate_maps") / "ac.usmap").string();
  slam::saveMap(*apart.maps[0].map, path, slam::separateMaps(apart.maps));

  std::vector<std::unique_ptr<slam::Pipeline>> separate;
  std::unique_ptr<slam::Pipeline> first = slam::loadMap(path, nullptr, &separate);
  ASSERT_EQ(separate.size(), 1u);
  EXPECT_EQ(first->keyframes().size(), na);
  EXPECT_EQ(separate[0]->keyframes().size(), nc);
  EXPECT_EQ(separate[0]->keyframes().back().pose.x, apart.maps[1].map->keyframes().back().pose.x);
  // Loaded and written again, the same bytes; loaded without asking for them, the first map alone.
  EXPECT_EQ(slam::encodeMap(*first, {separate[0].get()}), slam::encodeMap(*apart.maps[0].map, slam::separateMaps(apart.maps)));
  EXPECT_EQ(slam::loadMap(path)->keyframes().size(), na);

  {
    // The maps of one file were searched for in each other when it was written: merged again
    // with nothing new, they are not searched again.
    std::vector<std::unique_ptr<slam::Pipeline>> sep;
    std::vector<slam::NamedMap> same;
    same.push_back({slam::loadMap(path, nullptr, &sep), {path}, 0});
    for (auto& m : slam::namedSeparateMaps(std::move(sep), path, 0)) same.push_back(std::move(m));
    ASSERT_EQ(same.size(), 2u);
    EXPECT_EQ(same[1].sessions.front(), path + " (separate map 1)");
    const slam::MergedMaps again = slam::mergeMaps(std::move(same));
    ASSERT_EQ(again.maps.size(), 2u);
    ASSERT_EQ(again.sessions.size(), 1u);
    EXPECT_FALSE(again.sessions[0].contains("place_searches")) << again.sessions[0].dump();
  }

  // B drives from A's part to C's: merged after them, it joins A, and then C joins the two.
  std::vector<slam::NamedMap> three;
  three.push_back({std::move(first), {"A"}});
  three.push_back({std::move(separate[0]), {"C"}});
  three.push_back({session(at[0], kCuts[2] - kCuts[0] + 100), {"B"}});
  const size_t nb = three[2].map->keyframes().size();
  slam::MergedMaps linked = slam::mergeMaps(std::move(three));
  ASSERT_EQ(linked.maps.size(), 1u);
  EXPECT_EQ(linked.maps[0].sessions, (std::vector<std::string>{"A", "B", "C"}));
  ASSERT_EQ(linked.sessions.size(), 2u);
  EXPECT_EQ(linked.sessions[0].at("name").asString(), "B");
  EXPECT_EQ(linked.sessions[1].at("name").asString(), "C");
  EXPECT_EQ(linked.sessions[1].at("into").asString(), "A");
  slam::Pipeline& map = *linked.maps[0].map;
  map.finish();
  ASSERT_EQ(map.keyframes().size(), na + nb + nc);

  // C, placed by the link, lies where the one run over the whole excerpt has it.
  double worst = 0;
  for (size_t i = na + nb; i < map.keyframes().size(); ++i) {
    const slam::Keyframe& k = map.keyframes()[i];
    common::Pose2 truth;
    ASSERT_TRUE(evaluation::interpolatePose(e.full->scanTrajectory(), k.timestamp, 1.0, truth)) << k.timestamp;
    worst = std::max(worst, std::hypot(k.pose.x - truth.x, k.pose.y - truth.y));
  }
  EXPECT_LT(worst, 0.3);
  std::cerr << "A " << na << ", B " << nb << ", C " << nc << " keyframes; C at most " << worst << " m from the one run\n";
}
