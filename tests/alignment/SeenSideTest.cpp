// A surface is seen from its front only: the test on one pair, the sensor positions a point set
// carries through a change of frame, and two views of a facade with pillars from the two ends of
// its street, which see opposite faces of each pillar.
#include <gtest/gtest.h>

#include <cmath>

#include "alignment/SyntheticScan.h"
#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/AlignmentCovariance.h"
#include "urbanslam/alignment/LineNormals.h"
#include "urbanslam/alignment/ScanModel.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;

namespace {

// A street along x, 16 m between its facades; a pillar 1 m wide every 4 m on either side.
ua::test::World streetOfPillars() { return ua::test::pillaredStreetWorld(-7, 9, -60, 80); }

}  // namespace

TEST(SeenSide, SensorsOnOppositeSidesOfALineMakeNoPair) {
  ua::LineNormal wall;
  wall.n = {0, -1};  // the sign is arbitrary
  wall.valid = true;
  ua::ScanPoint ref;
  ref.p = {0, 5};
  ref.origin = {0, 0};
  const double tol = 10 * M_PI / 180;
  EXPECT_TRUE(ua::seenFromSameSide(wall, ref, {8, 1}, tol));     // both below the wall
  EXPECT_FALSE(ua::seenFromSameSide(wall, ref, {1, 10}, tol));   // above it, steeply
  EXPECT_TRUE(ua::seenFromSameSide(wall, ref, {20, 5.5}, tol));  // above it, nearly edge-on (1.4°)
  EXPECT_FALSE(ua::seenFromSameSide(wall, ref, {20, 9}, tol));   // above it, 11°
  ref.origin = {-30, 5.5};                                       // the reference's own view edge-on
  EXPECT_TRUE(ua::seenFromSameSide(wall, ref, {1, 0}, tol));
  ref.origin = {0, 0};
  EXPECT_TRUE(ua::seenFromSameSide(wall, ref, {1, 10}, -1));  // the test off
  EXPECT_TRUE(ua::seenFromSameSide(ua::LineNormal{}, ref, {1, 10}, tol));
}

TEST(SeenSide, APointSetKeepsWhereItsPointsWereSeenFrom) {
  urbanslam::io::LaserScan scan = ua::test::simulateScan(streetOfPillars(), {3, 1, 0.4});
  scan.sensor_pose = {1.5, 0.2, 0.1};
  const ua::PointSet in_vehicle = ua::pointSetFromScan(scan, {}, true);
  ASSERT_FALSE(in_vehicle.empty());
  for (const auto& q : in_vehicle) {
    EXPECT_NEAR(q.origin.x(), 1.5, 1e-12);
    EXPECT_NEAR(q.origin.y(), 0.2, 1e-12);
    EXPECT_NEAR((q.p - q.origin).norm(), q.range_m, 1e-9);
  }
  const ua::PointSet moved = ua::transformed(in_vehicle, {10, -2, M_PI / 2});
  EXPECT_NEAR(moved[0].origin.x(), 10 - 0.2, 1e-12);
  EXPECT_NEAR(moved[0].origin.y(), -2 + 1.5, 1e-12);
  EXPECT_NEAR((moved[0].p - moved[0].origin).norm(), in_vehicle[0].range_m, 1e-9);
}

TEST(SeenSide, OppositeViewsOfPillarsDoNotSlideByAPillarsWidth) {
  const ua::test::World street = streetOfPillars();
  const uc::Pose2 a{0, 0, 0}, b{20, 0.5, M_PI};
  const auto scan_a = ua::test::simulateScan(street, a), scan_b = ua::test::simulateScan(street, b);
  const uc::Pose2 truth = uc::between(a, b);
  // From guesses up to a metre off along the street. With the test, the pillars' fronts and
  // corners, which both views see, place them within 0.3 m. Without it, the faces of the pillars
  // that face west (seen from the west end) pair with those that face east (seen from the other
  // end), a pillar's width apart: a confident alignment a metre off.
  int confident_and_wrong = 0;
  for (const bool test : {true, false}) {
    ua::AlignerOptions o;
    o.method = ua::Method::PlIcp;
    o.min_constraint_ratio = 0.15;
    o.icp.seen_side_tolerance_deg = o.covariance.seen_side_tolerance_deg = test ? 10 : -1;
    for (const double dx : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
      const ua::AlignmentResult r = ua::align(scan_a, scan_b, {truth.x + dx, truth.y, truth.phi}, o);
      const double along = r.transform.x - truth.x;
      if (test) {
        EXPECT_TRUE(r.converged) << "from " << dx << " m: " << r.failure_reason;
        EXPECT_LT(std::abs(along), 0.3) << "from " << dx << " m, sigma " << std::sqrt(r.cov(0, 0));
      } else if (r.converged && std::abs(along) > 0.5 && std::sqrt(r.cov(0, 0)) < 0.2) {
        ++confident_and_wrong;
      }
    }
  }
  EXPECT_GE(confident_and_wrong, 1);
}

TEST(SeenSide, TheCovarianceCountsThePairsAsIcpMakesThem) {
  const ua::test::World street = streetOfPillars();
  const uc::Pose2 a{0, 0, 0}, b{20, 0.5, M_PI};
  const auto pa = ua::pointSetFromScan(ua::test::simulateScan(street, a), {}),
             pb = ua::pointSetFromScan(ua::test::simulateScan(street, b), {});
  const uc::Pose2 truth = uc::between(a, b), off = uc::compose({-1, 0, 0}, truth);  // a pillar's width along
  ua::CovarianceOptions with, without;
  without.seen_side_tolerance_deg = -1;
  const auto sigma_along = [&](const uc::Pose2& z, const ua::CovarianceOptions& o) {
    return std::sqrt(ua::alignmentCovariance(pa, pb, z, {}, true, o)(0, 0));
  };
  // At the truth the opposite faces are a pillar's width apart, beyond the association gate:
  // the test changes next to nothing.
  EXPECT_NEAR(sigma_along(truth, with), sigma_along(truth, without), 0.01);
  // A pillar's width off they are paired: counted, they would make the pose look known along the
  // street to centimetres; left out, it is not, and the constraint test refuses it.
  EXPECT_LT(sigma_along(off, without), 0.1);
  EXPECT_GT(sigma_along(off, with), 0.25);
  EXPECT_GT(ua::translationConstraintRatio(pa, pb, off, without), 0.15);
  EXPECT_LT(ua::translationConstraintRatio(pa, pb, off, with), 0.15);
}
