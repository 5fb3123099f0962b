// ICP, PL-ICP, CRF-match and the Aligner on synthetic scans from known poses, and the degenerate
// inputs that must fail cleanly.
#include <gtest/gtest.h>

#include "urbanslam/common/RigidFit.h"

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/LU>

#include "alignment/SyntheticScan.h"
#include "urbanslam/alignment/Aligner.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;
using ua::test::simulateScan;

namespace {

struct Pair {
  urbanslam::io::LaserScan a, b;
  uc::Pose2 truth;  // pose of B in A
};

Pair roomPair(const uc::Pose2& pa, const uc::Pose2& pb, double noise = 0.01) {
  const auto world = ua::test::roomWorld();
  ua::test::ScanSpec spec;
  spec.noise_m = noise;
  Pair p;
  p.a = simulateScan(world, pa, spec);
  spec.seed = 11;
  p.b = simulateScan(world, pb, spec);
  p.truth = uc::between(pa, pb);
  return p;
}

void expectNear(const uc::Pose2& est, const uc::Pose2& truth, double tol_m, double tol_rad, const std::string& what) {
  EXPECT_NEAR(est.x, truth.x, tol_m) << what;
  EXPECT_NEAR(est.y, truth.y, tol_m) << what;
  EXPECT_NEAR(uc::wrapToPi(est.phi - truth.phi), 0.0, tol_rad) << what;
}

uc::Pose2 perturb(const uc::Pose2& p, double dx, double dy, double dphi) { return {p.x + dx, p.y + dy, uc::wrapToPi(p.phi + dphi)}; }

}  // namespace

TEST(LeastSquares, ExactTransformFromPairs) {
  const uc::Pose2 T{1.5, -0.7, 0.9};
  const ua::Rigid2 R = ua::Rigid2::fromPose(T);
  std::vector<Eigen::Vector2d> src = {{0, 0}, {1, 0}, {0, 2}, {-3, 1}}, dst;
  for (const auto& s : src) dst.push_back(R * s);
  uc::Pose2 est;
  ASSERT_TRUE(uc::fitRigid2D(src, dst, {1, 1, 1, 1}, &est));
  expectNear(est, T, 1e-12, 1e-12, "closed form");
  EXPECT_FALSE(uc::fitRigid2D({{0, 0}}, {{1, 1}}, {1}, &est));
  EXPECT_FALSE(uc::fitRigid2D(src, dst, {0, 0, 0, 0}, &est));
}

class MethodTest : public ::testing::TestWithParam<ua::Method> {};

// Every method recovers a moderate offset in a room with walls, corners and clutter.
TEST_P(MethodTest, RecoversKnownPoseInRoom) {
  const std::vector<std::pair<uc::Pose2, uc::Pose2>> poses = {
      {{-3, 0, 0.2}, {-2.2, 0.4, 0.35}},
      {{0, -1, 1.2}, {0.5, -0.6, 1.0}},
      {{-5, 2, -0.5}, {-4.4, 1.5, -0.3}},
  };
  ua::AlignerOptions o;
  o.method = GetParam();
  for (const auto& [pa, pb] : poses) {
    const Pair p = roomPair(pa, pb);
    const uc::Pose2 guess = perturb(p.truth, 0.25, -0.2, 0.08);
    const auto r = ua::align(p.a, p.b, guess, o);
    EXPECT_TRUE(r.converged) << ua::methodName(o.method) << ": " << r.failure_reason;
    // CRF-match alone is a coarse alignment on ~100 subsampled points; point-to-point ICP is
    // biased by the different sampling of the two scans; point-to-line is the most precise.
    const bool coarse = o.method == ua::Method::Crf;
    const bool p2p = o.method == ua::Method::Icp;
    expectNear(r.transform, p.truth, coarse ? 0.1 : p2p ? 0.05 : 0.03, coarse ? 0.02 : p2p ? 0.01 : 0.005, ua::methodName(o.method));
    EXPECT_TRUE(r.cov.allFinite());
    EXPECT_GT(r.cov.determinant(), 0);
    EXPECT_GT(r.matches, coarse ? 30 : 150);
  }
}

INSTANTIATE_TEST_SUITE_P(All, MethodTest, ::testing::Values(ua::Method::Icp, ua::Method::PlIcp, ua::Method::Crf, ua::Method::CrfIcp),
                         [](const auto& info) {
                           std::string n = ua::methodName(info.param);
                           for (auto& c : n) {
                             if (c == '+') c = '_';
                           }
                           return n;
                         });

// The reason for CRF-match: it needs no guess, so a large initial error is no problem.
TEST(CrfMatch, LargeInitialErrorRecoveredByCrfPlusIcp) {
  const Pair p = roomPair({-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  ua::AlignerOptions o;
  o.method = ua::Method::CrfIcp;
  const auto r = ua::align(p.a, p.b, perturb(p.truth, 1.0, -1.0, 0.5), o);
  ASSERT_TRUE(r.converged) << r.failure_reason;
  expectNear(r.transform, p.truth, 0.05, 0.01, "crf+icp");
}

TEST(CrfMatch, DiagnosticsAndIndices) {
  const Pair p = roomPair({0, -1, 1.2}, {0.5, -0.6, 1.0});
  ua::ScanModelOptions so;
  const auto a = ua::pointSetFromScan(p.a, so), b = ua::pointSetFromScan(p.b, so);
  ua::CrfDiagnostics d;
  const auto r = ua::crfMatch(a, b, {}, ua::CrfOptions{}, &d);
  ASSERT_TRUE(r.converged) << r.failure_reason;
  EXPECT_LE(d.nodes, 160);
  EXPECT_GT(d.edges, d.nodes);
  EXPECT_GE(d.inliers, 20);
  for (const auto& m : r.matches) {
    ASSERT_GE(m.moving, 0);
    ASSERT_LT(m.moving, static_cast<int>(b.size()));
    ASSERT_GE(m.reference, 0);
    ASSERT_LT(m.reference, static_cast<int>(a.size()));
    EXPECT_GT(m.weight, 0);
  }
}

TEST(CrfMatch, ShapeFeaturesInvariantToTransform) {
  const Pair p = roomPair({-3, 0, 0.2}, {-3, 0, 0.2}, 0.0);
  const auto a = ua::pointSetFromScan(p.a, ua::ScanModelOptions{});
  const auto moved = ua::transformed(a, {3.0, -2.0, 1.1});
  ua::SubsamplingOptions so;
  const auto fa = ua::crfShapeFeatures(ua::subsample(a, so), {0.3, 1.0});
  const auto fb = ua::crfShapeFeatures(ua::subsample(moved, so), {0.3, 1.0});
  ASSERT_EQ(fa.size(), fb.size());
  for (size_t i = 0; i < fa.size(); ++i) {
    for (size_t k = 0; k < 2; ++k) {
      ASSERT_EQ(std::isfinite(fa[i][k]), std::isfinite(fb[i][k]));
      if (std::isfinite(fa[i][k])) {
        EXPECT_NEAR(fa[i][k], fb[i][k], 1e-9);
      }
    }
  }
}

TEST(Icp, PointToLineNeedsFewerIterations) {
  const Pair p = roomPair({-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  const auto a = ua::pointSetFromScan(p.a, {}), b = ua::pointSetFromScan(p.b, {});
  const auto guess = perturb(p.truth, 0.3, 0.2, -0.05);
  const auto r1 = ua::icp(a, b, guess, {});
  const auto r2 = ua::plIcp(a, b, guess, {});
  ASSERT_TRUE(r1.converged && r2.converged) << r1.failure_reason << " / " << r2.failure_reason;
  EXPECT_LT(r2.iterations, r1.iterations);
}

TEST(Icp, RobustKernelsAllConverge) {
  const Pair p = roomPair({-5, 2, -0.5}, {-4.4, 1.5, -0.3}, 0.02);
  const auto a = ua::pointSetFromScan(p.a, {}), b = ua::pointSetFromScan(p.b, {});
  for (auto k : {ua::RobustKernel::None, ua::RobustKernel::Huber, ua::RobustKernel::Cauchy}) {
    ua::IcpOptions o;
    o.kernel = k;
    const auto r = ua::icp(a, b, perturb(p.truth, 0.2, 0.1, 0.05), o);
    EXPECT_TRUE(r.converged) << r.failure_reason;
    expectNear(r.transform, p.truth, 0.05, 0.01, "kernel");
  }
}

TEST(Icp, ARunThatCannotReachTheCallersFractionIsGivenUpEarly) {
  // A pair that aligns: the same answer with and without the caller's fraction.
  const Pair p = roomPair({-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  const auto a = ua::pointSetFromScan(p.a, {}), b = ua::pointSetFromScan(p.b, {});
  ua::IcpOptions plain, giving_up;
  giving_up.abandon_below_fraction = 0.5;
  const auto guess = perturb(p.truth, 0.3, 0.2, -0.05);
  const auto r1 = ua::plIcp(a, b, guess, plain), r2 = ua::plIcp(a, b, guess, giving_up);
  ASSERT_TRUE(r1.converged && r2.converged) << r1.failure_reason << " / " << r2.failure_reason;
  EXPECT_EQ(r1.transform.x, r2.transform.x);
  EXPECT_EQ(r1.transform.phi, r2.transform.phi);
  EXPECT_EQ(r1.matches.size(), r2.matches.size());
  // A scan of a corridor against the room: run to the end, it matches under half of its points;
  // given up, it says so, in fewer iterations.
  ua::test::ScanSpec spec;
  const auto c = ua::pointSetFromScan(simulateScan(ua::test::corridorWorld(), {1, 0, 0}, spec), {});
  const auto full = ua::plIcp(a, c, {}, plain), early = ua::plIcp(a, c, {}, giving_up);
  EXPECT_LT(static_cast<double>(full.matches.size()), 0.5 * static_cast<double>(c.size()));
  EXPECT_FALSE(early.converged);
  EXPECT_NE(early.failure_reason.find("the caller needs 50 %"), std::string::npos) << early.failure_reason;
  EXPECT_LT(early.iterations, full.iterations);
}

// --- Degenerate inputs: a clear failure, a finite transform, no crash. ---

class DegenerateTest : public ::testing::TestWithParam<ua::Method> {};

TEST_P(DegenerateTest, CorridorIsReportedDegenerate) {
  const auto world = ua::test::corridorWorld();
  const auto a = simulateScan(world, {0, 0, 0.1});
  const auto b = simulateScan(world, {1.0, 0.1, 0.15});
  ua::AlignerOptions o;
  o.method = GetParam();
  const auto r = ua::align(a, b, uc::between({0, 0, 0.1}, {1.0, 0.1, 0.15}), o);
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.failure_reason.empty());
  EXPECT_TRUE(std::isfinite(r.transform.x) && std::isfinite(r.transform.y) && std::isfinite(r.transform.phi));
  EXPECT_TRUE(r.cov.allFinite());
}

TEST_P(DegenerateTest, EmptyMaxRangeOnePointAndNaNFailCleanly) {
  ua::AlignerOptions o;
  o.method = GetParam();
  const Pair good = roomPair({-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  urbanslam::io::LaserScan empty;
  urbanslam::io::LaserScan all_max = good.a;
  for (auto& r : all_max.ranges) r = static_cast<float>(all_max.max_range_m);
  urbanslam::io::LaserScan one = good.a;
  for (size_t i = 0; i < one.size(); ++i) one.valid[i] = i == 100;
  urbanslam::io::LaserScan nans = good.a;
  for (auto& r : nans.ranges) r = std::numeric_limits<float>::quiet_NaN();
  const uc::Pose2 guess{0.5, 0.1, 0.1};
  for (const auto* bad : {&empty, &all_max, &one, &nans}) {
    for (int side = 0; side < 2; ++side) {
      const auto r = side == 0 ? ua::align(*bad, good.b, guess, o) : ua::align(good.a, *bad, guess, o);
      EXPECT_FALSE(r.converged);
      EXPECT_FALSE(r.failure_reason.empty());
      EXPECT_TRUE(std::isfinite(r.transform.x) && std::isfinite(r.transform.y) && std::isfinite(r.transform.phi));
      EXPECT_TRUE(r.cov.allFinite());
    }
  }
  // A NaN guess.
  const auto r = ua::align(good.a, good.b, {std::nan(""), 0, 0}, o);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isfinite(r.transform.x));
}

INSTANTIATE_TEST_SUITE_P(All, DegenerateTest, ::testing::Values(ua::Method::Icp, ua::Method::PlIcp, ua::Method::Crf, ua::Method::CrfIcp),
                         [](const auto& info) {
                           std::string n = ua::methodName(info.param);
                           for (auto& c : n) {
                             if (c == '+') c = '_';
                           }
                           return n;
                         });

TEST(Aligner, ParseMethodNames) {
  for (auto m : {ua::Method::Icp, ua::Method::PlIcp, ua::Method::Crf, ua::Method::CrfIcp}) EXPECT_EQ(ua::parseMethod(ua::methodName(m)), m);
  EXPECT_THROW(ua::parseMethod("ndt"), std::invalid_argument);
}

// Hostile input: random lengths (0-400 beams), NaN / inf / negative / huge ranges, zero or
// negative beam spacing, valid flags of the wrong length. Every method must return finite
// numbers and never crash.
TEST(Aligner, RandomGarbageNeverCrashes) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1.0f, 0.0f, 1e30f, 80.0f};
  auto randomScan = [&]() {
    urbanslam::io::LaserScan s;
    const int n = static_cast<int>(u(rng) * 400);
    s.angle_min_rad = -M_PI / 2;
    s.angle_increment_rad = u(rng) < 0.2 ? (u(rng) < 0.5 ? 0.0 : -0.01) : M_PI / std::max(1, n);
    s.max_range_m = u(rng) < 0.1 ? 0.0 : 30.0;
    for (int i = 0; i < n; ++i) {
      s.ranges.push_back(u(rng) < 0.2 ? specials[static_cast<int>(u(rng) * 6)] : static_cast<float>(u(rng) * 20));
      s.valid.push_back(u(rng) < 0.9);
    }
    if (u(rng) < 0.1) s.valid.resize(s.valid.size() / 2);
    return s;
  };
  for (int k = 0; k < 40; ++k) {
    const auto a = randomScan(), b = randomScan();
    for (auto m : {ua::Method::Icp, ua::Method::PlIcp, ua::Method::Crf, ua::Method::CrfIcp}) {
      ua::AlignerOptions o;
      o.method = m;
      const auto r = ua::align(a, b, {u(rng), u(rng), u(rng)}, o);
      ASSERT_TRUE(std::isfinite(r.transform.x) && std::isfinite(r.transform.y) && std::isfinite(r.transform.phi));
      ASSERT_TRUE(r.cov.allFinite());
      if (!r.converged) {
        EXPECT_FALSE(r.failure_reason.empty());
      }
    }
  }
}
