#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "SyntheticScan.h"
#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/ViewOverlap.h"

using namespace urbanslam;
using alignment::test::World;

namespace {

// A city street along x: facades 8 m either side of the centre line with doorways, parked cars
// and trees, and a cross street at x = 40.
World street() {
  World w;
  for (double x = -120; x < 120; x += 12) {
    if (x >= 36 && x < 48) continue;  // the cross street
    w.push_back({{x, 8}, {x + 10, 8}});
    w.push_back({{x + 10, 8}, {x + 10, 9.5}});
    w.push_back({{x, -8}, {x + 9, -8}});
    w.push_back({{x + 9, -8}, {x + 9, -9}});
  }
  for (double x = -100; x < 100; x += 23) alignment::test::addBox(w, x, 5.5, x + 4.5, 7.3);
  for (double x = -90; x < 100; x += 17) alignment::test::addPolygon(w, x, -6.5, 0.4, 8);
  return w;
}

alignment::PointSet points(const io::LaserScan& scan) { return alignment::pointSetFromScan(scan, alignment::ScanModelOptions{}, true); }

// Independent reference: the share of B's points that lie within the gate of one of A's points
// (brute force), at one pose: what an alignment ending there could match at most.
double matchableShare(const alignment::PointSet& a, const alignment::PointSet& b, const common::Pose2& b_in_a, double gate) {
  const double c = std::cos(b_in_a.phi), s = std::sin(b_in_a.phi);
  int n = 0;
  for (const auto& q : b) {
    const Eigen::Vector2d m(c * q.p.x() - s * q.p.y() + b_in_a.x, s * q.p.x() + c * q.p.y() + b_in_a.y);
    for (const auto& r : a)
      if ((r.p - m).squaredNorm() <= gate * gate) {
        ++n;
        break;
      }
  }
  return static_cast<double>(n) / static_cast<double>(b.size());
}

io::LaserScan scanAt(const World& w, const common::Pose2& pose, unsigned seed) {
  alignment::test::ScanSpec spec;
  spec.max_range_m = 50;
  spec.seed = seed;
  return alignment::test::simulateScan(w, pose, spec);
}

}  // namespace

TEST(ViewOverlap, OppositeLanesCannotBeAlignedAndTheSameLaneCan) {
  const World w = street();
  const common::Pose2 a_pose{0, -3, 0}, opposite{-4, 3, M_PI}, behind{-6, -2.5, 0.05};
  const io::LaserScan a = scanAt(w, a_pose, 1);
  const alignment::PointSet pa = points(a), pb_opposite = points(scanAt(w, opposite, 2)), pb_behind = points(scanAt(w, behind, 3));
  const alignment::ViewSector sector = alignment::viewSector(pa, a.sensor_pose);
  alignment::PoseRegion region;
  region.cov = Eigen::Vector3d(0.5, 0.5, std::pow(3 * M_PI / 180, 2)).asDiagonal();  // 0.7 m, 3 degrees

  // The car that has just passed in the opposite lane looks back along the street: the reference
  // finds no pose of the region where half of its points fall near A's points, and the bound
  // proves that none exists.
  region.center = common::between(a_pose, opposite);
  double best = 0;
  std::mt19937 rng(5);
  std::normal_distribution<double> nd(0, 1);
  for (int k = 0; k < 300; ++k) {
    const common::Pose2 t{region.center.x + 0.7 * nd(rng), region.center.y + 0.7 * nd(rng), region.center.phi + 3 * M_PI / 180 * nd(rng)};
    best = std::max(best, matchableShare(pa, pb_opposite, t, 0.2));
  }
  EXPECT_LT(best, 0.5);
  EXPECT_FALSE(alignment::mayMatchShare(sector, pb_opposite, region, 0.5));

  // The car 6 m behind in the same lane sees the same facades: it may match, and it does.
  region.center = common::between(a_pose, behind);
  EXPECT_TRUE(alignment::mayMatchShare(sector, pb_behind, region, 0.5));
  alignment::AlignerOptions ao;
  ao.method = alignment::Method::PlIcp;
  const auto r = alignment::alignPointSets(pa, pb_behind, region.center, ao);
  ASSERT_TRUE(r.converged) << r.failure_reason;
  EXPECT_GE(r.matchedFraction(), 0.5);
  EXPECT_LE(r.matchedFraction(), alignment::shareInView(sector, pb_behind, r.transform, ao.icp.gate_final_m) + 1e-12);
}

// Soundness against the brute-force reference: whenever some sampled pose of the region lets a
// share of B's points lie near A's points, the bound must not deny that share.
TEST(ViewOverlap, NeverDeniesAShareThatSomePoseOfTheRegionReaches) {
  const World w = street();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ux(-60, 60), uy(-5, 5), uphi(-M_PI, M_PI), usig(0.1, 3.0), udeg(0.5, 40);
  std::normal_distribution<double> nd(0, 1);
  int denied = 0, checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const common::Pose2 pa_pose{ux(rng), uy(rng), uphi(rng)}, pb_pose{pa_pose.x + 10 * nd(rng), uy(rng), uphi(rng)};
    const io::LaserScan a = scanAt(w, pa_pose, 100 + trial), b = scanAt(w, pb_pose, 200 + trial);
    const alignment::PointSet pa = points(a), pb = points(b);
    if (pa.size() < 20 || pb.size() < 20) continue;
    alignment::PoseRegion region;
    const double sxy = usig(rng), sphi = udeg(rng) * M_PI / 180;
    region.cov = Eigen::Vector3d(sxy * sxy, 0.5 * sxy * sxy, sphi * sphi).asDiagonal();
    region.center = common::between(pa_pose, pb_pose);
    region.center.x += sxy * nd(rng);
    const double k = std::sqrt(region.chi2);
    double best = 0;
    for (int s = 0; s < 200; ++s) {
      // Poses inside the region: a direction on the unit sphere, scaled to within the gate.
      Eigen::Vector3d d(nd(rng), nd(rng), nd(rng));
      d *= k * std::cbrt(std::uniform_real_distribution<double>(0, 1)(rng)) / d.norm();
      const common::Pose2 t{region.center.x + sxy * d.x(), region.center.y + std::sqrt(0.5) * sxy * d.y(),
                            region.center.phi + sphi * d.z()};
      best = std::max(best, matchableShare(pa, pb, t, 0.2));
    }
    const alignment::ViewSector sector = alignment::viewSector(pa, a.sensor_pose);
    // The share the best sampled pose reached is the tightest test of the bound.
    for (const double share : {0.1, 0.3, 0.5, 0.7, best})
      if (best >= share) {
        ++checked;
        if (!alignment::mayMatchShare(sector, pb, region, share)) ++denied;
      }
  }
  EXPECT_GT(checked, 40);
  EXPECT_EQ(denied, 0);
}

TEST(ViewOverlap, DegenerateInputIsNeverDenied) {
  const World w = street();
  const io::LaserScan a = scanAt(w, {0, 0, 0}, 1);
  const alignment::PointSet pa = points(a), pb = points(scanAt(w, {0, 0, M_PI}, 2));
  const alignment::ViewSector sector = alignment::viewSector(pa, a.sensor_pose);
  alignment::PoseRegion region;
  region.center = {0, 0, M_PI};
  region.cov = Eigen::Matrix3d::Zero();  // not positive definite: no region to bound over
  EXPECT_TRUE(alignment::mayMatchShare(sector, pb, region, 0.5));
  region.cov(0, 0) = std::nan("");
  EXPECT_TRUE(alignment::mayMatchShare(sector, pb, region, 0.5));
  // Nothing to match: a share above zero is out of reach, zero is not.
  EXPECT_FALSE(alignment::mayMatchShare(alignment::viewSector({}, {}), pb, alignment::PoseRegion{}, 0.5));
  EXPECT_TRUE(alignment::mayMatchShare(sector, pb, alignment::PoseRegion{}, 0.0));
  // A full turn of heading uncertainty: the opposite view becomes reachable.
  region.cov = Eigen::Vector3d(0.25, 0.25, 4.0).asDiagonal();
  region.center = {0, 0, M_PI};
  EXPECT_TRUE(alignment::mayMatchShare(sector, pb, region, 0.5));
}
