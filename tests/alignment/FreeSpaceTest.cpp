#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "SyntheticScan.h"
#include "urbanslam/alignment/FreeSpace.h"

using namespace urbanslam;
using alignment::test::World;

namespace {

// Independent reference: the share of B's points (placed by b_in_a) that the *world* says lie in
// A's free space, i.e. the segment from A's sensor to the point crosses no wall and ends more
// than the margin in front of the wall A's beam hits. Ray casting against the map, not A's scan.
double worldConflict(const World& w, const common::Pose2& pose_a, const io::LaserScan& a, const io::LaserScan& b,
                     const common::Pose2& b_in_a, const alignment::FreeSpaceOptions& o) {
  const common::Pose2 b_world = common::compose(pose_a, b_in_a);
  int tested = 0, conflicts = 0;
  for (const io::Point2& p : io::scanToPoints(b, true)) {
    const common::Pose2 q = common::compose(b_world, common::Pose2{p.x, p.y, 0});
    const double dx = q.x - pose_a.x, dy = q.y - pose_a.y, r = std::hypot(dx, dy);
    const double bearing = std::atan2(dy, dx) - pose_a.phi;
    const double beam = std::round((std::atan2(std::sin(bearing), std::cos(bearing)) - a.angle_min_rad) / a.angle_increment_rad);
    if (r < o.min_range_m || beam < 1 || beam > static_cast<double>(a.size()) - 2) continue;
    // The wall distance along the three beams around the point, from the world.
    double wall = std::numeric_limits<double>::infinity();
    for (int k = -1; k <= 1; ++k) {
      const double ang = pose_a.phi + a.bearing(static_cast<size_t>(beam) + k);
      const io::LaserScan one =
          alignment::test::simulateScan(w, {pose_a.x, pose_a.y, ang}, {2, 1e-9, a.max_range_m, 0.0, 1});  // beam 0 along ang
      if (!one.valid[0]) {
        wall = -1;
        break;
      }
      wall = std::min(wall, static_cast<double>(one.ranges[0]));
    }
    if (wall < 0) continue;
    ++tested;
    if (r < wall - o.margin_m - o.margin_fraction * wall) ++conflicts;
  }
  return tested ? static_cast<double>(conflicts) / tested : 0.0;
}

}  // namespace

TEST(FreeSpace, TrueAlignmentHasNoConflict) {
  const World w = alignment::test::roomWorld();
  const common::Pose2 pa{-3, 0, 0.1}, pb{-1.5, 0.8, 0.6};
  const auto a = alignment::test::simulateScan(w, pa), b = alignment::test::simulateScan(w, pb, {361, M_PI, 30, 0.01, 9});
  const common::Pose2 truth = common::between(pa, pb);
  const auto c = alignment::freeSpaceConflict(a, b, truth);
  EXPECT_GT(c.tested, 100);
  EXPECT_LT(c.fraction(), 0.01);
  EXPECT_LT(alignment::mutualFreeSpaceConflict(a, b, truth), 0.01);
}

TEST(FreeSpace, WrongAlignmentConflictsAsTheWorldSays) {
  const World w = alignment::test::roomWorld();
  const common::Pose2 pa{-3, 0, 0.1}, pb{-1.5, 0.8, 0.6};
  const auto a = alignment::test::simulateScan(w, pa), b = alignment::test::simulateScan(w, pb, {361, M_PI, 30, 0.01, 9});
  const alignment::FreeSpaceOptions o;
  for (const common::Pose2& wrong : {common::Pose2{2.5, 0.8, 0.5}, common::Pose2{1.5, -1.5, 0.3}, common::Pose2{1.5, 0.8, 1.2}}) {
    const auto c = alignment::freeSpaceConflict(a, b, wrong, o);
    const double reference = worldConflict(w, pa, a, b, wrong, o);
    EXPECT_GT(c.fraction(), 0.05) << wrong.x << " " << wrong.y << " " << wrong.phi;
    EXPECT_NEAR(c.fraction(), reference, 0.03) << wrong.x << " " << wrong.y << " " << wrong.phi;
  }
}

// Points behind what A saw (occluded for A) are no evidence against the match: B, beside A,
// sees the far wall behind a pillar that hides it from A. Those points lie in A's view, on
// beams that returned (from the pillar), beyond where the beams ended.
TEST(FreeSpace, OccludedPointsDoNotConflict) {
  World w = alignment::test::roomWorld();
  alignment::test::addBox(w, -1.2, -0.6, -0.8, 0.6);  // the pillar, 2 m ahead of A
  const common::Pose2 pa{-3, 0, 0}, pb{-3, 2.0, -0.3};
  const auto a = alignment::test::simulateScan(w, pa), b = alignment::test::simulateScan(w, pb);
  const common::Pose2 truth = common::between(pa, pb);
  // How many of B's points A cannot see: within the pillar's bearings from A, beyond the pillar.
  int occluded = 0;
  for (const io::Point2& p : io::scanToPoints(b, true)) {
    const common::Pose2 q = common::compose(truth, common::Pose2{p.x, p.y, 0});
    if (q.x > 2.3 && std::abs(std::atan2(q.y, q.x)) < std::atan2(0.5, 2.2)) ++occluded;
  }
  ASSERT_GT(occluded, 10) << "the scene does not hide part of B's view from A";
  const auto c = alignment::freeSpaceConflict(a, b, truth);
  EXPECT_GT(c.tested, occluded);
  EXPECT_EQ(c.conflicts, 0);
}

// A no-return says nothing unless the user says how far it saw free space.
TEST(FreeSpace, NoReturnsCountOnlyWhenConfigured) {
  const World w = alignment::test::roomWorld();
  const common::Pose2 pa{-3, 0, 0}, pb{-1, 0.5, 0.2};
  alignment::test::ScanSpec short_range;
  short_range.max_range_m = 4.0;  // most of A's beams end in no-returns
  const auto a = alignment::test::simulateScan(w, pa, short_range);
  const auto b = alignment::test::simulateScan(w, pb);
  const common::Pose2 wrong{-1.5, 0, 0};  // B's walls pulled 1.5 m into A's (open) view
  alignment::FreeSpaceOptions o;
  const auto unknown = alignment::freeSpaceConflict(a, b, wrong, o);
  o.no_return_free_m = 4.0;
  const auto known = alignment::freeSpaceConflict(a, b, wrong, o);
  EXPECT_GT(known.tested, unknown.tested);
  EXPECT_GT(known.conflicts, unknown.conflicts);
}

TEST(FreeSpace, EmptyAndNaNScansTestNothing) {
  const World w = alignment::test::roomWorld();
  auto a = alignment::test::simulateScan(w, {0, 0, 0});
  io::LaserScan empty;
  EXPECT_EQ(alignment::freeSpaceConflict(empty, a, {}).tested, 0);
  EXPECT_EQ(alignment::freeSpaceConflict(a, empty, {}).tested, 0);
  EXPECT_EQ(alignment::mutualFreeSpaceConflict(a, empty, {}), 0.0);
  io::LaserScan nan = a;
  for (auto& r : nan.ranges) r = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(alignment::freeSpaceConflict(nan, a, {}).tested, 0);
}

// Where beam 0 points must not matter: the same 360° scan starting at -180° and at 0°.
TEST(FreeSpace, FullCircleScanStartingAtZero) {
  const World w = alignment::test::roomWorld();
  const common::Pose2 pa{-3, 0, 0}, pb{-1, 0.5, 0.2};
  alignment::test::ScanSpec full;
  full.beams = 361;
  full.fov_rad = 2 * M_PI;  // beam 0 at -180°, beam 360 again at +180°
  auto a = alignment::test::simulateScan(w, pa, full);
  a.ranges.pop_back();
  a.valid.pop_back();
  io::LaserScan rotated = a;  // beam j at j degrees
  for (size_t j = 0; j < 360; ++j) {
    rotated.ranges[j] = a.ranges[(j + 180) % 360];
    rotated.valid[j] = a.valid[(j + 180) % 360];
  }
  rotated.angle_min_rad = 0;
  const auto b = alignment::test::simulateScan(w, pb);
  const common::Pose2 wrong{1.0, 1.5, -0.4};
  const auto c1 = alignment::freeSpaceConflict(a, b, wrong), c2 = alignment::freeSpaceConflict(rotated, b, wrong);
  EXPECT_GT(c1.tested, 300);
  EXPECT_GT(c1.conflicts, 0);
  // Only points at the seam beams (no neighbour on one side: behind in a, ahead in rotated) differ.
  EXPECT_NEAR(c2.tested, c1.tested, 10);
  EXPECT_NEAR(c2.conflicts, c1.conflicts, 10);
}
