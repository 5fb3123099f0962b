// The prebuilt reference (kd-tree + normals) and the bounded nearest-neighbour search must give
// exactly what the unshared path gives: they exist for speed only.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "alignment/SyntheticScan.h"
#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/NearestNeighbours.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;

namespace {

// The nearest point's squared distance, by looking at every point.
double bruteForceNearest(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : pts) best = std::min(best, (p - q).squaredNorm());
  return best;
}

}  // namespace

// A scan's returns: dense near the vehicle, sparse out to 200 m (beyond what the search's cell
// grid covers around the median: those points and the queries near them take the kd-tree).
TEST(NearestNeighbours, BoundedSearchAgreesWithBruteForceOverAWideSparseSet) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> near(-6, 6), far(-200, 200);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 800; ++i) pts.push_back({near(rng), near(rng)});
  for (int i = 0; i < 300; ++i) pts.push_back({far(rng), far(rng) * 0.1});
  const ua::NearestNeighbours index(pts);
  for (int k = 0; k < 4000; ++k) {
    Eigen::Vector2d q(near(rng) * 2.5, near(rng) * 2.5);
    if (k % 2 == 0) q = pts[static_cast<size_t>(k) % pts.size()] + Eigen::Vector2d(0.1 * near(rng) / 6, 0.1 * near(rng) / 6);
    const double bound = k % 3 == 0 ? 0.09 : (k % 3 == 1 ? 0.0004 : 0.25);
    const double best = bruteForceNearest(pts, q);
    int j = -1;
    double d2 = -1;
    ASSERT_EQ(index.nearestWithin(q, bound, &j, &d2), best <= bound) << k;
    if (best <= bound) {
      EXPECT_EQ(d2, best) << k;
    }
  }
}

TEST(NearestNeighbours, BoundedSearchAgreesWithBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  std::vector<Eigen::Vector2d> pts(500);
  for (auto& p : pts) p = {u(rng), u(rng)};
  pts.push_back(pts[7]);  // a duplicate: ties must not confuse the bound
  // Points on the grid's cell edges (every 0.1 m from the lowest point) and queries there.
  for (int i = 0; i < 20; ++i) pts.push_back(Eigen::Vector2d(-4.0 + 0.1 * i, 1.0));
  const ua::NearestNeighbours index(pts);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d q =
        k % 7 == 0 ? Eigen::Vector2d(-4.0 + 0.05 * (k % 40), 1.0 + 0.01 * (k % 5)) : Eigen::Vector2d(u(rng) * 1.4, u(rng) * 1.4);
    // Bounds the cell grid answers (up to 0.3 m: the matchers' gates) and ones for the kd-tree.
    const double bounds[] = {0.0001, 0.01, 0.09, 0.1, 4.0};
    const double bound = bounds[k % 5];
    const double best = bruteForceNearest(pts, q);
    int j = -1;
    double d2 = -1;
    const bool found = index.nearestWithin(q, bound, &j, &d2);
    ASSERT_EQ(found, best <= bound) << k;
    if (found) {
      EXPECT_EQ(d2, best);
      EXPECT_EQ((pts[j] - q).squaredNorm(), best);
    }
  }
  // A point exactly at the bound is within it (the bound is inclusive, as ICP's gate test was).
  const Eigen::Vector2d q = pts[0] + Eigen::Vector2d(0.05, 0);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : pts) best = std::min(best, (p - q).squaredNorm());
  int j = -1;
  double d2 = -1;
  ASSERT_TRUE(index.nearestWithin(q, best, &j, &d2));
  EXPECT_EQ(d2, best);
  EXPECT_FALSE(index.nearestWithin(q, std::nextafter(best, 0.0), &j, &d2));
}

// A refinement's queries: each scan point asked again at every iteration, a little (sometimes a
// lot) from where it was last asked, with the bound changing. The memo's answers are the brute
// force's (found, squared distance) and the plain search's (the index: of two points at the same
// distance the grid answers the lower, the kd-tree the one its order finds), whether or not a
// search ran.
TEST(NearestNeighbours, MemoGivesTheSearchsAnswerAsTheQueryWanders) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5, 5), unit(-1, 1);
  std::vector<Eigen::Vector2d> pts;
  // Walls sampled every centimetre or two (a refinement's usual reference), scattered points,
  // and a duplicate (a tie at every query).
  for (int i = 0; i < 400; ++i) pts.push_back({-3.0 + 0.015 * i, 2.0 + 0.002 * unit(rng)});
  for (int i = 0; i < 300; ++i) pts.push_back({1.5 + 0.002 * unit(rng), -3.0 + 0.02 * i});
  for (int i = 0; i < 300; ++i) pts.push_back({u(rng), u(rng)});
  pts.push_back(pts[250]);
  const ua::NearestNeighbours index(pts);
  const auto truth = [&](const Eigen::Vector2d& q, double bound, double* d2) {
    *d2 = bruteForceNearest(pts, q);
    return *d2 <= bound;
  };
  size_t searched_less = 0;
  for (int walk = 0; walk < 300; ++walk) {
    ua::NearestNeighbours::Memo memo;
    Eigen::Vector2d q = walk % 3 == 0 ? pts[static_cast<size_t>(walk) % pts.size()] : Eigen::Vector2d(u(rng), u(rng));
    for (int step = 0; step < 30; ++step) {
      const double scale = step % 10 == 9 ? 0.5 : (step % 2 == 0 ? 1e-4 : 3e-3);  // sub-millimetre, millimetres, a jump
      q += scale * Eigen::Vector2d(unit(rng), unit(rng));
      if (walk % 3 == 0 && step == 15) q = pts[250];  // exactly on the duplicated point
      // Bounds the cell grid answers, and ones beyond its reach (the kd-tree's: ICP's first gates).
      const double bounds[] = {0.09, 0.01, 0.0001, 0.16, 0.25, 4.0};
      const double bound = bounds[(walk + step / 5) % 6];
      int j = -1;
      double dt = 0, d2 = -1;
      const Eigen::Vector2d before = memo.query;
      const bool expected = truth(q, bound, &dt);
      int jp = -1;
      double dp = -1;
      ASSERT_EQ(index.nearestWithin(q, bound, &jp, &dp), expected) << walk << " " << step;
      ASSERT_EQ(index.nearestWithin(q, bound, &memo, &j, &d2), expected) << walk << " " << step;
      if (expected) {
        EXPECT_EQ(j, jp) << walk << " " << step;
        EXPECT_EQ((pts[static_cast<size_t>(j)] - q).squaredNorm(), dt) << walk << " " << step;
        EXPECT_EQ(d2, dt) << walk << " " << step;
      }
      if (memo.query == before && step > 0) ++searched_less;
    }
  }
  // Most small steps keep their answer without a search: the memo is what makes it cheaper.
  EXPECT_GT(searched_less, 300u * 30u / 3);
  // A tie the kd-tree answers (a bound beyond the grid's): the plain search's choice of the two.
  ua::NearestNeighbours::Memo memo;
  int j = -1, jp = -1;
  double d2 = -1, dp = -1;
  const Eigen::Vector2d q = pts[250] + Eigen::Vector2d(0, 0.001);
  ASSERT_TRUE(index.nearestWithin(q, 4.0, &j, &d2));
  ASSERT_TRUE(index.nearestWithin(q, 4.0, &memo, &jp, &dp));
  EXPECT_TRUE(j == 250 || j == static_cast<int>(pts.size()) - 1);
  EXPECT_EQ(jp, j);
  EXPECT_EQ(dp, d2);
}

// The next nearest point can lie in the next cell of the search's grid while the nearest is so
// close that the plain search never looks there: the memo's search must, or a query that then
// crosses into that cell keeps a stale answer. Cells are 0.1 m from the lowest point.
TEST(NearestNeighbours, MemoSeesTheNextNearestAcrossACellEdge) {
  const std::vector<Eigen::Vector2d> pts = {{0, 0}, {0.099, 0.05}, {0.101, 0.05}, {0.5, 0.5}};
  const ua::NearestNeighbours index(pts);
  ua::NearestNeighbours::Memo memo;
  int j = -1;
  double d2 = -1;
  ASSERT_TRUE(index.nearestWithin({0.0985, 0.05}, 0.09, &memo, &j, &d2));
  EXPECT_EQ(j, 1);
  ASSERT_TRUE(index.nearestWithin({0.1005, 0.05}, 0.09, &memo, &j, &d2));
  EXPECT_EQ(j, 2);
  EXPECT_EQ(d2, (pts[2] - Eigen::Vector2d(0.1005, 0.05)).squaredNorm());
}

TEST(IndexedReference, SameResultAsAligningThePointSets) {
  const auto world = ua::test::roomWorld();
  ua::test::ScanSpec spec;
  const auto a = ua::test::simulateScan(world, {0, 0, 0}, spec);
  spec.seed = 5;
  const auto b = ua::test::simulateScan(world, {0.4, -0.2, 0.15}, spec);
  for (const auto method : {ua::Method::Icp, ua::Method::PlIcp, ua::Method::CrfIcp}) {
    ua::AlignerOptions o;
    o.method = method;
    const auto pa = ua::pointSetFromScan(a, o.scan, o.in_vehicle_frame);
    const auto pb = ua::pointSetFromScan(b, o.scan, o.in_vehicle_frame);
    const ua::IndexedReference ref(pa);
    // Several alignments against one reference, as the pipeline's retries do.
    for (const uc::Pose2 guess : {uc::Pose2{0.3, -0.1, 0.1}, uc::Pose2{0, 0, 0}, uc::Pose2{0.6, 0, 0.3}}) {
      const auto plain = ua::alignPointSets(pa, pb, guess, o);
      const auto shared = ua::alignPointSets(ref, pb, guess, o);
      ASSERT_TRUE(plain.converged) << ua::methodName(method);
      EXPECT_EQ(plain.transform.x, shared.transform.x);
      EXPECT_EQ(plain.transform.y, shared.transform.y);
      EXPECT_EQ(plain.transform.phi, shared.transform.phi);
      EXPECT_EQ(plain.matches, shared.matches);
      EXPECT_TRUE(plain.cov == shared.cov) << ua::methodName(method);
      EXPECT_EQ(plain.constraint_ratio, shared.constraint_ratio);
    }
  }
}

TEST(IndexedReference, NormalsPerOptionsStayValid) {
  const auto a = ua::test::simulateScan(ua::test::roomWorld(), {0, 0, 0});
  const ua::IndexedReference ref(ua::pointSetFromScan(a, {}, true));
  ua::LineNormalOptions loose;
  loose.line_tolerance_m = 0.2;
  const auto& first = ref.normals({});
  const auto& second = ref.normals(loose);  // a second set must not move the first
  const auto expect_first = ua::computeLineNormals(ref.points(), {});
  const auto expect_second = ua::computeLineNormals(ref.points(), loose);
  ASSERT_EQ(first.size(), expect_first.size());
  ASSERT_EQ(second.size(), expect_second.size());
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].piece, expect_first[i].piece);
    EXPECT_EQ(second[i].piece, expect_second[i].piece);
  }
  EXPECT_EQ(&ref.normals({}), &first);  // cached, not recomputed
}
