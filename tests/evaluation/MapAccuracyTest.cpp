#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/evaluation/MapAccuracy.h"

namespace urbanslam::evaluation {
namespace {

// Points at known perpendicular offsets from the walls of a square room (and one beyond an
// end, whose nearest point is the corner): the metric must return those distances.
TEST(MapAccuracy, DistancesToKnownWalls) {
  const std::vector<WallSegment> walls = {{0, 0, 10, 0}, {10, 0, 10, 10}, {10, 10, 0, 10}, {0, 10, 0, 0}};
  std::vector<io::MapPoint> pts;
  std::vector<double> expected;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> along(1.0, 9.0), off(0.0, 0.8);
  for (int i = 0; i < 400; ++i) {
    const double a = along(rng), d = off(rng);
    switch (i % 4) {
      case 0:
        pts.push_back({static_cast<float>(a), static_cast<float>(d), 0});
        break;
      case 1:
        pts.push_back({static_cast<float>(10 - d), static_cast<float>(a), 0});
        break;
      case 2:
        pts.push_back({static_cast<float>(a), static_cast<float>(10 + d), 0});
        break;
      default:
        pts.push_back({static_cast<float>(-d), static_cast<float>(a), 0});
        break;
    }
    expected.push_back(d);
  }
  pts.push_back({13, -4, 0});  // 5 m from the corner (10, 0): the cap
  expected.push_back(5.0);
  // The map in a frame rotated and shifted from the walls': carried back by to_truth.
  const common::Pose2 to_truth{2.0, -1.0, 0.3};
  std::vector<io::MapPoint> in_map;
  const common::Pose2 inv = common::inverse(to_truth);
  for (const auto& p : pts) {
    const common::Pose2 q = common::compose(inv, {p.x, p.y, 0});
    in_map.push_back({static_cast<float>(q.x), static_cast<float>(q.y), 0});
  }
  const MapAccuracyMetrics m = mapAccuracy(in_map, to_truth, walls, 5.0);
  ASSERT_EQ(m.points, pts.size());
  double sum = 0;
  size_t near = 0;
  for (double d : expected) sum += d, near += d <= 0.1 ? 1 : 0;
  EXPECT_NEAR(m.mean_m, sum / static_cast<double>(expected.size()), 1e-5);
  EXPECT_NEAR(m.within_0_1_m, static_cast<double>(near) / static_cast<double>(expected.size()), 1e-9);
  EXPECT_NEAR(m.beyond_1_m, 1.0 / static_cast<double>(expected.size()), 1e-9);
  std::sort(expected.begin(), expected.end());
  EXPECT_NEAR(m.median_m, expected[(expected.size() - 1) / 2], 1e-5);
}

TEST(MapAccuracy, LoopRecallCountsRevisitedScansJoinedByAClosure) {
  // Two revisits: scans at 100.0-100.2 s see the place of 10.0-10.2 s, scan 200 s that of 50 s.
  const std::vector<TrueLoop> truth = {{10.0, 100.0}, {10.1, 100.1}, {10.2, 100.2}, {10.3, 100.2}, {50.0, 200.0}};
  std::vector<LoopRow> closures(3);
  closures[0] = {1, 9, 10.05, 100.1, true, {}};   // joins the first revisit
  closures[1] = {2, 12, 60.0, 200.0, true, {}};   // right later time, wrong earlier place
  closures[2] = {3, 13, 50.0, 200.0, false, {}};  // right, but rejected
  const LoopRecall r = loopRecall(closures, truth, 2.0);
  EXPECT_EQ(r.revisited_scans, 4u);
  EXPECT_EQ(r.closed_scans, 3u);
  EXPECT_NEAR(r.recall, 0.75, 1e-12);
}

TEST(MapAccuracy, RevisitRecallCountsRevisitsOfEnoughPathOnceEach) {
  // The truth drives along x at 10 m/s from t = 0. Three revisits (scans 0.1 s apart): 100-110 s
  // (100 m, closed once in its middle), 200-210 s (100 m, its only closure rejected) and 300-303 s
  // (30 m: too short to count, though unclosed). A gap of more than a second splits a revisit.
  std::vector<io::StampedPose> path;
  for (int k = 0; k <= 4000; ++k) path.push_back({0.1 * k, {1.0 * k, 0.0, 0.0}});
  std::vector<TrueLoop> truth;
  for (double t0 : {100.0, 200.0, 300.0})
    for (double t = t0; t <= t0 + (t0 == 300.0 ? 3.0 : 10.0) + 1e-9; t += 0.1) truth.push_back({t - 90.0, t});
  std::vector<LoopRow> closures(2);
  closures[0] = {1, 9, 15.0, 105.0, true, {}};
  closures[1] = {2, 12, 115.0, 205.0, false, {}};
  const RevisitRecall r = revisitRecall(closures, truth, path, 50.0, 1.0, 2.0);
  EXPECT_EQ(r.revisits, 2u);
  EXPECT_EQ(r.closed, 1u);
  ASSERT_EQ(r.unclosed.size(), 1u);
  EXPECT_NEAR(r.unclosed[0].t_start, 200.0, 1e-9);
  EXPECT_NEAR(r.unclosed[0].t_end, 210.0, 1e-9);
  EXPECT_NEAR(r.unclosed[0].path_m, 100.0, 1.0);  // the truth's samples within the revisit's span
  // With 25 m enough, the short one counts too (unclosed), and a closure at 301 s closes it.
  EXPECT_EQ(revisitRecall(closures, truth, path, 25.0).revisits, 3u);
  closures.push_back({3, 14, 211.0, 301.0, true, {}});
  const RevisitRecall all = revisitRecall(closures, truth, path, 25.0);
  EXPECT_EQ(all.closed, 2u);
  EXPECT_EQ(all.unclosed.size(), 1u);
}

}  // namespace
}  // namespace urbanslam::evaluation
