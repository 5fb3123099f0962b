#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "../alignment/SyntheticScan.h"
#include "urbanslam/alignment/FreeSpace.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/PathSubmaps.h"

using namespace urbanslam;
using alignment::test::World;

namespace {

// A street along x, facades 8 m either side of the centre line, one building design repeated
// every 12 m on each side (a recessed door per building; trees, one per building on the south
// side and two on the north: the sides of the trees that face the street are what views from the
// two lanes both see that fixes where along the street they are, a door's two sides being seen
// from one end each). With `cross_street`, a cross street at x in [-10, 2) breaks the repetition
// and a building stands at its end.
World street(bool cross_street) {
  World w;
  for (double x = -180; x < 180; x += 12) {
    const bool gap = cross_street && x >= -12 && x < 0;
    if (gap) continue;
    w.push_back({{x, 8}, {x + 8, 8}});
    w.push_back({{x + 8, 8}, {x + 8, 9.5}});
    w.push_back({{x + 8, 9.5}, {x + 10, 9.5}});
    w.push_back({{x + 10, 9.5}, {x + 10, 8}});
    w.push_back({{x + 10, 8}, {x + 12, 8}});
    w.push_back({{x, -8}, {x + 5, -8}});
    w.push_back({{x + 5, -8}, {x + 5, -9}});
    w.push_back({{x + 5, -9}, {x + 12, -9}});
    alignment::test::addPolygon(w, x + 3, -6.5, 0.4, 8);
    alignment::test::addPolygon(w, x + 2, 6.5, 0.4, 8);
    alignment::test::addPolygon(w, x + 8, 6.5, 0.4, 8);
  }
  if (cross_street) alignment::test::addBox(w, -14, 24, 4, 30);
  return w;
}

// The earlier visit drives east along y = -3 (keyframes 0..120 at x = -60..60), the current one
// west along y = +3 (keyframes 121..241 at x = 60..-60): opposite lanes, each scan a front 180°
// laser, the map's poses the truth.
std::unique_ptr<slam::Map> twoVisits(const World& w) {
  auto map = std::make_unique<slam::Map>(nullptr, 2.0);
  alignment::test::ScanSpec spec;
  spec.max_range_m = 50;
  size_t index = 0;
  for (int visit = 0; visit < 2; ++visit)
    for (int s = 0; s <= 120; ++s) {
      const common::Pose2 pose = visit == 0 ? common::Pose2{-60.0 + s, -3, 0} : common::Pose2{60.0 - s, 3, M_PI};
      spec.seed = static_cast<unsigned>(index + 1);
      map->addKeyframe({index, static_cast<double>(index), pose, true, false, {}},
                       io::CompactScan(alignment::test::simulateScan(w, pose, spec)));
      ++index;
    }
  return map;
}

constexpr size_t kEarlier = 60;        // x = 0 on the earlier visit
constexpr size_t kCurrent = 121 + 48;  // x = 12 on the current one

bool refused(const slam::SubmapCheck& c, const common::Pose2& z) {
  const common::Pose2 d = common::between(z, c.measurement);
  return c.ambiguous || (c.aligned && (std::hypot(d.x, d.y) > 0.3 || std::abs(d.phi) > 3 * M_PI / 180));
}

}  // namespace

TEST(PathSubmaps, SubmapsHoldEachVisitsScansInTheKeyframesFrame) {
  const auto map = twoVisits(street(false));
  slam::PathSubmapOptions o;
  const alignment::PointSet before = slam::pathSubmap(*map, kEarlier, 0, 120, o);
  ASSERT_GT(before.size(), 100u);
  // Every point lies on a wall of the world, seen from the earlier keyframe's frame (x = 0,
  // y = -3): south facades at y = -8 or -9 there are at -5 or -6, north ones at 11 or 12.5.
  int on_facades = 0;
  for (const auto& p : before) {
    const double y = p.p.y() - 3;  // back to the world's y
    if (std::abs(std::abs(y) - 8) < 0.2 || std::abs(y + 9) < 0.2 || std::abs(y - 9.5) < 0.2) ++on_facades;
  }
  EXPECT_GT(on_facades, static_cast<int>(0.7 * static_cast<double>(before.size())));
  // One point per voxel.
  for (size_t i = 1; i < before.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      ASSERT_FALSE(std::floor(before[i].p.x() / o.voxel_m) == std::floor(before[j].p.x() / o.voxel_m) &&
                   std::floor(before[i].p.y() / o.voxel_m) == std::floor(before[j].p.y() / o.voxel_m));
}

// In a street of one repeated design, the true closure and one a building further along align
// the two visits' submaps equally well: the check cannot tell them apart and refuses both.
TEST(PathSubmaps, ARepeatedStreetIsAmbiguous) {
  const auto map = twoVisits(street(false));
  const common::Pose2 truth = common::between(map->keyframes()[kEarlier].pose, map->keyframes()[kCurrent].pose);
  const slam::SubmapCheck c = slam::alignPathSubmaps(*map, kEarlier, kCurrent, truth, 40, {});
  EXPECT_TRUE(c.aligned);
  EXPECT_TRUE(c.ambiguous);
  // Within the reach of the first restart only (shorter than the street's period): nothing else.
  EXPECT_FALSE(slam::alignPathSubmaps(*map, kEarlier, kCurrent, truth, 7, {}).ambiguous);
}

// A cross street within the submaps' reach settles it: the true closure holds, the one a
// building along is refused.
TEST(PathSubmaps, ACrossStreetTellsTheTrueClosureFromItsAlias) {
  const auto map = twoVisits(street(true));
  const common::Pose2 truth = common::between(map->keyframes()[kEarlier].pose, map->keyframes()[kCurrent].pose);
  const slam::SubmapCheck right = slam::alignPathSubmaps(*map, kEarlier, kCurrent, truth, 40, {});
  EXPECT_TRUE(right.aligned);
  EXPECT_FALSE(refused(right, truth)) << right.measurement.x - truth.x << " " << right.measurement.y - truth.y;
  const common::Pose2 alias = common::compose(common::Pose2{12, 0, 0}, truth);  // a building further east
  EXPECT_TRUE(refused(slam::alignPathSubmaps(*map, kEarlier, kCurrent, alias, 40, {}), alias));
}

// Through the loop closer: a closure far from what the filter knows (the two visits joined by
// a link known to 5 m, placed 2 m wrong) is measured by the two visits' submaps, aligned from
// the scans' own alignment; with the test off, by the scans alone.
TEST(PathSubmaps, AFarClosureIsMeasuredByTheSubmaps) {
  const auto map = twoVisits(street(true));
  const auto& kf = map->keyframes();
  esdf::Esdf filter;
  filter.initialise(esdf::toVec(kf[0].pose), esdf::Mat3::Identity() * 1e-9);
  const esdf::Mat3 tight = esdf::Vec3(1e-4, 1e-4, 1e-6).asDiagonal(), loose = esdf::Vec3(25, 25, 1e-4).asDiagonal();
  for (size_t j = 1; j < kf.size(); ++j) {
    common::Pose2 z = common::between(kf[j - 1].pose, kf[j].pose);
    if (j == 121) z.x += 2;  // the link between the visits
    filter.augmentRelative(static_cast<int>(j - 1), esdf::toVec(z), (j == 121 ? loose : tight).inverse());
  }
  filter.recover();
  const common::Pose2 truth = common::between(kf[kEarlier].pose, kf[kCurrent].pose);
  slam::LoopClosureOptions o;
  o.submap_check_path_m = 0;
  const slam::LoopClosureRecord scans = slam::LoopCloser(o).tryClose(filter, *map, kEarlier, kCurrent, false);
  ASSERT_EQ(scans.reason, slam::ClosureReason::None);
  ASSERT_GT(scans.prior_sigma_m, o.appearance_min_sigma_m);
  o.submap_check_path_m = 30;
  const slam::LoopClosureRecord submaps = slam::LoopCloser(o).tryClose(filter, *map, kEarlier, kCurrent, false);
  ASSERT_EQ(submaps.reason, slam::ClosureReason::None);
  slam::PathSubmapOptions po;
  const slam::SubmapCheck c = slam::alignPathSubmaps(*map, kEarlier, kCurrent, scans.measurement, 3 * scans.prior_sigma_m, po);
  ASSERT_TRUE(c.aligned);
  EXPECT_NEAR(submaps.measurement.x, c.measurement.x, 1e-9);
  EXPECT_NEAR(submaps.measurement.y, c.measurement.y, 1e-9);
  EXPECT_NEAR(submaps.measurement.phi, c.measurement.phi, 1e-12);
  // Against the truth, the submaps' measurement is at least as good as the scans'.
  const common::Pose2 es = common::between(truth, scans.measurement), em = common::between(truth, submaps.measurement);
  EXPECT_LT(std::hypot(em.x, em.y), 0.05);
  EXPECT_LE(std::hypot(em.x, em.y), std::hypot(es.x, es.y) + 0.01);
  // The submaps' measurement enters only where the two scans agree on free space there: they do
  // at the submaps' alignment, and would not one building further along (the alias a street of
  // one design offers), where the closure keeps the scans' own measurement.
  alignment::FreeSpaceOptions fo;
  fo.margin_m = o.free_space_margin_m;
  fo.no_return_free_m = o.free_space_no_return_m;
  const auto conflict = [&](const common::Pose2& z) {
    return alignment::mutualFreeSpaceConflict(map->scan(kEarlier), map->scan(kCurrent), z, fo);
  };
  EXPECT_LE(conflict(c.measurement), o.max_free_space_conflict);
  EXPECT_NEAR(submaps.free_space_conflict, conflict(c.measurement), 1e-12);
  EXPECT_GT(conflict(common::compose(common::Pose2{12, 0, 0}, c.measurement)), 2 * o.max_free_space_conflict);
}
