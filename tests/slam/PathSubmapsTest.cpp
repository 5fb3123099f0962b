#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <vector>

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

// A visit: the world its scans see and its keyframes' poses.
struct Visit {
  const World* world;
  std::vector<common::Pose2> poses;
};

// Poses a metre apart along y = `y` from x = from_x to to_x, heading that way.
std::vector<common::Pose2> along(double y, int from_x, int to_x) {
  std::vector<common::Pose2> out;
  const int step = from_x <= to_x ? 1 : -1;
  for (int x = from_x;; x += step) {
    out.push_back({static_cast<double>(x), y, step > 0 ? 0.0 : M_PI});
    if (x == to_x) break;
  }
  return out;
}

// The visits' keyframes in turn, numbered from 0, each scan a front 180° laser of range_m in its
// visit's world, the map's poses the truth.
std::unique_ptr<slam::Map> mapOf(const std::vector<Visit>& visits, double range_m) {
  auto map = std::make_unique<slam::Map>(nullptr, 2.0);
  alignment::test::ScanSpec spec;
  spec.max_range_m = range_m;
  size_t index = 0;
  for (const Visit& v : visits)
    for (const common::Pose2& pose : v.poses) {
      spec.seed = static_cast<unsigned>(index + 1);
      map->addKeyframe({index, static_cast<double>(index), pose, true, false, {}},
                       io::CompactScan(alignment::test::simulateScan(*v.world, pose, spec)));
      ++index;
    }
  return map;
}

// The earlier visit drives east along y = -3 (keyframes 0..120 at x = -60..60), the current one
// west along y = +3 (keyframes 121..241 at x = 60..-60): opposite lanes, a 50 m laser.
std::unique_ptr<slam::Map> twoVisits(const World& w) { return mapOf({{&w, along(-3, -60, 60)}, {&w, along(3, 60, -60)}}, 50); }

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

namespace {

// A street whose design repeats every 48 m: four buildings of 12 m, each with its recessed door
// at another place, then the four again; facades 8 m either side of the centre line.
World streetOfPeriod48() {
  World w;
  const double doors[] = {1.0, 6.5, 3.0, 8.5};
  for (int b = -20; b < 20; ++b) {
    const double x = 12.0 * b, door = doors[((b % 4) + 4) % 4];
    w.push_back({{x, 8}, {x + door, 8}});
    w.push_back({{x + door, 8}, {x + door, 9.5}});
    w.push_back({{x + door, 9.5}, {x + door + 2, 9.5}});
    w.push_back({{x + door + 2, 9.5}, {x + door + 2, 8}});
    w.push_back({{x + door + 2, 8}, {x + 12, 8}});
    w.push_back({{x, -8}, {x + 12 - door - 2, -8}});
    w.push_back({{x + 12 - door - 2, -8}, {x + 12 - door - 2, -9.5}});
    w.push_back({{x + 12 - door - 2, -9.5}, {x + 12 - door, -9.5}});
    w.push_back({{x + 12 - door, -9.5}, {x + 12 - door, -8}});
    w.push_back({{x + 12 - door, -8}, {x + 12, -8}});
  }
  return w;
}

// Two visits east along y = -3, each from x = -120 to 120 (keyframes 0..240, then 241..481), a
// 50 m laser.
std::unique_ptr<slam::Map> twoVisitsEast(const World& w) { return mapOf({{&w, along(-3, -120, 120)}, {&w, along(-3, -120, 120)}}, 50); }

}  // namespace

// A closure one period (48 m) off along a street that repeats beyond the submaps' 60 m: the two
// submaps align at it as well as at the truth. Only an earlier submap that reaches as far as the
// gate admits holds the stretch the restarts shift the current submap to, where it matches as
// well: the closure is ambiguous, the true one as much as its alias; within a reach short of the
// period, neither is.
TEST(PathSubmaps, AStreetThatRepeatsBeyondTheSubmapsIsAmbiguousWithinTheGatesReach) {
  const auto map = twoVisitsEast(streetOfPeriod48());
  constexpr size_t kCurrent = 241 + 120;  // x = 0 on the second visit
  // The true closure (the first visit's keyframe at x = 0) and its alias (the one at x = -48,
  // measured at the same place): each aligns where it started, and is ambiguous within a reach
  // of 60 m, not within 20 m.
  for (const size_t earlier : {size_t{120}, size_t{72}}) {
    const common::Pose2 z{};
    const slam::SubmapCheck wide = slam::alignPathSubmaps(*map, earlier, kCurrent, z, 60, {});
    ASSERT_TRUE(wide.aligned);
    EXPECT_LT(std::hypot(wide.measurement.x, wide.measurement.y), 0.1) << earlier;
    EXPECT_TRUE(wide.ambiguous) << earlier;
    EXPECT_FALSE(slam::alignPathSubmaps(*map, earlier, kCurrent, z, 20, {}).ambiguous) << earlier;
  }
}

namespace {

// A street of 6 m buildings whose facades stand back by their own setback (0 to 2.4 m behind 8 m
// from the centre line, by the building's number and `design` (1 or 2), the buildings of design 2
// 3 m further back), a tree before each on either side; the buildings from x = -6 to 18 are of
// design 1 in every street.
World streetOfSetbacks(int design) {
  World w;
  double north_before = 8, south_before = -8;
  for (int b = -30; b < 30; ++b) {
    const double x = 6.0 * b;
    const int d = (b >= -1 && b < 3) ? 1 : design;
    const auto setback = [&](unsigned side) {
      unsigned h = static_cast<unsigned>(b + 100) * 2654435761u ^ static_cast<unsigned>(d) * 40503u ^ side * 97u;
      h ^= h >> 13;
      h *= 0x5bd1e995u;
      h ^= h >> 15;
      return 3.0 * (d - 1) + 0.6 * static_cast<double>(h % 5u);
    };
    const double north = 8 + setback(0), south = -8 - setback(1);
    alignment::test::addPolygon(w, x + 1 + setback(2), 6.5, 0.4, 8);  // a tree a building, where its design puts it
    alignment::test::addPolygon(w, x + 1 + setback(3), -6.5, 0.4, 8);
    w.push_back({{x, north_before}, {x, north}});
    w.push_back({{x, north}, {x + 6, north}});
    w.push_back({{x, south_before}, {x, south}});
    w.push_back({{x, south}, {x + 6, south}});
    north_before = north;
    south_before = south;
  }
  return w;
}

// The first visit east along the centre line from x = first_from_x to 120 in `first`, the
// second from x = -120 to 120 in `second` (keyframes 0..240, then 241..481, with the default
// start), a 16 m laser.
std::unique_ptr<slam::Map> visitsOf(const World& first, const World& second, int first_from_x = -120) {
  return mapOf({{&first, along(0, first_from_x, 120)}, {&second, along(0, -120, 120)}}, 16);
}

}  // namespace

// Two streets alike from x = -6 to 18 and nowhere else: scans at x = 0 (looking east) see the
// same, and the submaps of 60 m of path around them (the closure putting both at one place)
// share under a quarter of the current one's points. Two visits of one street agree there.
TEST(PathSubmaps, NeighbourhoodsOfTwoPlacesThatLookAlikeOnlyThereDisagree) {
  slam::PathSubmapOptions o;
  o.path_m = 60;
  const common::Pose2 z{};
  const auto same = visitsOf(streetOfSetbacks(1), streetOfSetbacks(1));
  const slam::SubmapCheck agree = slam::alignPathSubmaps(*same, 120, 361, z, 3, o);
  EXPECT_TRUE(agree.aligned);
  EXPECT_FALSE(agree.disagree);
  const auto other = visitsOf(streetOfSetbacks(1), streetOfSetbacks(2));
  const slam::SubmapCheck differ = slam::alignPathSubmaps(*other, 120, 361, z, 3, o);
  EXPECT_FALSE(differ.aligned);
  EXPECT_TRUE(differ.disagree);
}

// The earlier visit starts at the closure's place: the current submap's 60 m of path before it
// lie where that visit saw nothing (its laser looked ahead), and its points there are not
// counted: the two submaps agree. Counting every point, they would disagree.
TEST(PathSubmaps, WhereTheEarlierVisitSawNothingThereIsNothingToDisagreeWith) {
  const auto map = visitsOf(streetOfSetbacks(1), streetOfSetbacks(1), 0);  // keyframes 0..120, then 121..361
  constexpr size_t kStart = 0, kCurrent = 121 + 120;                       // x = 0 on both visits
  slam::PathSubmapOptions o;
  o.path_m = 60;
  EXPECT_FALSE(slam::alignPathSubmaps(*map, kStart, kCurrent, common::Pose2{}, 3, o).disagree);
  o.near_m = 1e3;
  EXPECT_TRUE(slam::alignPathSubmaps(*map, kStart, kCurrent, common::Pose2{}, 3, o).disagree);
}

// Through the loop closer: a closure far from what the filter knows (the two visits joined by a
// link known to 5 m) between the two streets, whose scans agree, is refused by the submaps; the
// same closure between two visits of one street is not.
TEST(PathSubmaps, AFarClosureBetweenPlacesWhoseNeighbourhoodsDisagreeIsRefused) {
  const auto reason = [](const slam::Map& map) {
    const auto& kf = map.keyframes();
    esdf::Esdf filter;
    filter.initialise(esdf::toVec(kf[0].pose), esdf::Mat3::Identity() * 1e-9);
    const esdf::Mat3 tight = esdf::Vec3(1e-4, 1e-4, 1e-6).asDiagonal(), loose = esdf::Vec3(25, 25, 1e-4).asDiagonal();
    for (size_t j = 1; j < kf.size(); ++j) {
      common::Pose2 z = common::between(kf[j - 1].pose, kf[j].pose);
      if (j == 241) z.x += 1;  // the link between the visits: the second visit's x = 0 put 1 m east of the first's
      filter.augmentRelative(static_cast<int>(j - 1), esdf::toVec(z), (j == 241 ? loose : tight).inverse());
    }
    filter.recover();
    slam::LoopClosureOptions o;
    o.submap_check_path_m = 60;
    const slam::LoopClosureRecord r = slam::LoopCloser(o).tryClose(filter, map, 120, 361, false);
    EXPECT_GT(r.prior_sigma_m, o.appearance_min_sigma_m);
    return r.reason;
  };
  EXPECT_EQ(reason(*visitsOf(streetOfSetbacks(1), streetOfSetbacks(2))), slam::ClosureReason::Submaps);
  EXPECT_EQ(reason(*visitsOf(streetOfSetbacks(1), streetOfSetbacks(1))), slam::ClosureReason::None);
}
