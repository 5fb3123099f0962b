#include <gtest/gtest.h>

#include <cmath>

#include "../alignment/SyntheticScan.h"
#include "urbanslam/evaluation/ClosureEvidence.h"

using namespace urbanslam;
namespace sim = urbanslam::alignment::test;

namespace {

// Two scans of the same room from known poses: the true relative pose is the independent truth.
struct Pair {
  io::LaserScan a, b;
  common::Pose2 truth;
};

Pair roomPair() {
  const auto world = sim::roomWorld();
  const common::Pose2 pa{-1.0, 0.0, 0.1}, pb{0.2, 0.6, 0.35};
  sim::ScanSpec spec;
  Pair p{sim::simulateScan(world, pa, spec), {}, common::between(pa, pb)};
  spec.seed = 11;
  p.b = sim::simulateScan(world, pb, spec);
  return p;
}

const common::Pose2 kOff{0.3, -0.2, 3.0 * M_PI / 180};  // a reference 0.36 m / 3° off

}  // namespace

// The reference is off, the run is right: PL-ICP from the reference's pose returns to the run's.
TEST(ClosureEvidence, ScansFavourTheRunWhenTheReferenceIsOff) {
  const Pair p = roomPair();
  const auto e = evaluation::weighClosure(p.a, p.b, p.truth, common::compose(p.truth, kOff));
  EXPECT_EQ(e.verdict, "run");
  const auto d = common::between(p.truth, e.from_reference);
  EXPECT_LT(std::hypot(d.x, d.y), 0.03);
  EXPECT_LT(std::abs(d.phi), 0.3 * M_PI / 180);
  EXPECT_GT(e.matched_fraction, 0.8);
  EXPECT_LE(e.run_conflict, e.reference_conflict);
}

// The run is off, the reference is right: PL-ICP stays at the reference's pose.
TEST(ClosureEvidence, ScansFavourTheReferenceWhenTheRunIsOff) {
  const Pair p = roomPair();
  const auto e = evaluation::weighClosure(p.a, p.b, common::compose(p.truth, kOff), p.truth);
  EXPECT_EQ(e.verdict, "reference");
  EXPECT_LE(e.reference_conflict, e.run_conflict);
}

TEST(ClosureEvidence, AKeyframeWithoutAScanSaysNothing) {
  const Pair p = roomPair();
  const auto e = evaluation::weighClosure(p.a, io::LaserScan{}, p.truth, common::compose(p.truth, kOff));
  EXPECT_EQ(e.verdict, "no_scans");
}
