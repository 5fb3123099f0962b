// The local matcher (odometry prior + scan evidence) against independent references: the
// prior's box bound against a brute-force minimum, the branch and bound against an exhaustive
// search of the same window, and matches of ray-cast scans against their true relative pose.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <random>

#include "SyntheticScan.h"
#include "urbanslam/alignment/CorrelativeSearch.h"
#include "urbanslam/alignment/HeadingCorrections.h"
#include "urbanslam/alignment/LikelihoodGrid.h"
#include "urbanslam/alignment/MotionPrior.h"
#include "urbanslam/alignment/OdometryOutvotes.h"
#include "urbanslam/alignment/PriorScanMatcher.h"
#include "urbanslam/alignment/ScanModel.h"

namespace urbanslam::alignment {
namespace {

// The heading step the search takes (CorrelativeSearch.cpp): one that moves the median point by
// one cell. The exhaustive references enumerate the same headings.
double searchHeadingStep(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& pts) {
  std::vector<double> ranges;
  for (const auto& p : pts) ranges.push_back(p.norm());
  std::sort(ranges.begin(), ranges.end());
  const double far = std::max(grid.resolution(), ranges[static_cast<size_t>(0.5 * static_cast<double>(ranges.size() - 1))]);
  return std::acos(1.0 - grid.resolution() * grid.resolution() / (2 * far * far));
}

Eigen::Matrix3d correlatedCov() {
  Eigen::Matrix3d c;
  c << 0.04, 0.015, 0.004, 0.015, 0.02, -0.002, 0.004, -0.002, 0.01;
  return c;
}

TEST(MotionPrior, BoxMinimumMatchesBruteForce) {
  const MotionPrior prior({1, 2, 0.3}, correlatedCov(), 0.01, 1.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const double x0 = u(rng), y0 = u(rng), w = 0.05 + 0.5 * (u(rng) + 1), h = 0.05 + 0.5 * (u(rng) + 1), dphi = 0.3 * u(rng);
    double brute = 1e300;
    for (int i = 0; i <= 200; ++i)
      for (int j = 0; j <= 200; ++j) {
        const Eigen::Vector3d d(x0 + w * i / 200, y0 + h * j / 200, dphi);
        brute = std::min(brute, prior.mahalanobis2(d));
      }
    const double bound = prior.minMahalanobis2(x0, x0 + w, y0, y0 + h, dphi);
    EXPECT_LE(bound, brute + 1e-9);
    EXPECT_NEAR(bound, brute, 1e-3 * std::max(1.0, brute));
  }
}

TEST(MotionPrior, MixtureDensityAndWeight) {
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal();
  const MotionPrior prior({}, cov, 0.01, 2.0);
  const double gauss_peak = std::log(0.99) - 1.5 * std::log(2 * M_PI) - 0.5 * std::log(cov.determinant());
  const double m2 = 9.0;
  EXPECT_NEAR(prior.logDensity(m2), std::log(std::exp(gauss_peak - 0.5 * m2) + 0.01 / 2.0), 1e-9);
  EXPECT_NEAR(prior.gaussianWeight(0), 1.0, 1e-4);
  EXPECT_LT(prior.gaussianWeight(400), 1e-6);  // 20 sigma: only the uniform share explains it
  EXPECT_NEAR(prior.logDensity(1e6), std::log(0.01 / 2.0), 1e-9);
}

PointSet scanPoints(const test::World& world, const common::Pose2& pose, unsigned seed = 7) {
  test::ScanSpec spec;
  spec.seed = seed;
  return pointSetFromScan(test::simulateScan(world, pose, spec), ScanModelOptions{}, false);
}

TEST(CorrelativeSearch, BranchAndBoundFindsTheExhaustiveOptimum) {
  const test::World world = test::roomWorld();
  const PointSet ref = scanPoints(world, {0, 0, 0});
  PointSet cur = scanPoints(world, {0.4, -0.2, 0.15}, 9);
  std::vector<Eigen::Vector2d> pts;
  for (size_t i = 0; i < cur.size(); i += 6) pts.push_back(cur[i].p);  // a sparse set keeps the exhaustive loop short
  LikelihoodGridOptions go;
  go.resolution_m = 0.1;
  go.hit_sigma_m = 0.1;
  const LikelihoodGrid grid(ref, Eigen::Vector2d::Zero(), go);
  const MotionPrior prior({0.1, 0.1, 0.0}, Eigen::Vector3d(0.04, 0.04, 0.01).asDiagonal(), 0.01, 1.0);
  CorrelativeWindow window;
  window.half_width_m = 0.6;
  window.half_angle_rad = 0.25;
  const CorrelativeResult r = correlativeSearch(grid, pts, prior, window);
  // The same score over every pose of the same lattice.
  const double step = searchHeadingStep(grid, pts);
  const int k = static_cast<int>(std::ceil(window.half_angle_rad / step)),
            w = static_cast<int>(std::ceil(window.half_width_m / grid.resolution()));
  double best = -1e300;
  common::Pose2 best_pose;
  for (int a = -k; a <= k; ++a)
    for (int i = -w; i <= w; ++i)
      for (int j = -w; j <= w; ++j) {
        const common::Pose2 x{0.1 + i * grid.resolution(), 0.1 + j * grid.resolution(), a * step};
        const Eigen::Matrix2d R = Eigen::Rotation2Dd(x.phi).toRotationMatrix();
        double s = 0;
        for (const auto& p : pts) s += grid.score(R * p + Eigen::Vector2d(x.x, x.y));
        s += prior.logDensity(x);
        if (s > best) best = s, best_pose = x;
      }
  EXPECT_NEAR(r.score, best, 1e-3);
  EXPECT_NEAR(r.pose.x, best_pose.x, 1e-9);
  EXPECT_NEAR(r.pose.y, best_pose.y, 1e-9);
  EXPECT_NEAR(r.pose.phi, best_pose.phi, 1e-9);
  EXPECT_FALSE(r.below_min_score);

  // A floor below the optimum leaves the answer as it is; one above it, no answer.
  window.min_score = best - 5.0;
  const CorrelativeResult floored = correlativeSearch(grid, pts, prior, window);
  EXPECT_FALSE(floored.below_min_score);
  EXPECT_NEAR(floored.score, best, 1e-3);
  EXPECT_NEAR(floored.pose.x, best_pose.x, 1e-9);
  EXPECT_NEAR(floored.pose.y, best_pose.y, 1e-9);
  EXPECT_NEAR(floored.pose.phi, best_pose.phi, 1e-9);
  EXPECT_LE(floored.nodes, r.nodes);
  window.min_score = best + 0.01;
  EXPECT_TRUE(correlativeSearch(grid, pts, prior, window).below_min_score);
}

// A place search's window: no prior (flat), every heading, and a reach past the grid's edge, so
// that blocks inside the grid and blocks partly outside it are both scored; whole, and trimmed on
// some sides (a neighbouring window covers those). The answer is the best scan score over every
// pose of the lattice the window keeps, and the prior adds the same constant to every pose.
TEST(CorrelativeSearch, AFlatPriorFindsTheBestScanScoreOverEveryHeading) {
  const test::World world = test::roomWorld();
  const PointSet ref = scanPoints(world, {0, 0, 0});
  const PointSet cur = scanPoints(world, {0.3, 0.2, 2.0}, 9);
  std::vector<Eigen::Vector2d> pts;
  for (size_t i = 0; i < cur.size(); i += 8) pts.push_back(cur[i].p);
  const MotionPrior prior({0.2, 0.1, 0.0}, Eigen::Vector3d(1e8, 1e8, 1e8).asDiagonal(), 0.0, 1.0);
  struct Case {
    double radius;               // the grid's
    std::array<double, 4> trim;  // -x, +x, -y, +y
  };
  for (const Case& c :
       {Case{40.0, {0, 0, 0, 0}}, Case{6.0, {0, 0, 0, 0}}, Case{40.0, {0.4, 0.0, 0.0, 0.7}}, Case{40.0, {0.0, 0.5, 0.3, 0.0}}}) {
    SCOPED_TRACE(::testing::Message() << "radius " << c.radius << " trim " << c.trim[0] << " " << c.trim[1] << " " << c.trim[2] << " "
                                      << c.trim[3]);
    LikelihoodGridOptions go;
    go.resolution_m = 0.1;
    go.hit_sigma_m = 0.1;
    go.max_radius_m = c.radius;
    const LikelihoodGrid grid(ref, Eigen::Vector2d::Zero(), go);
    CorrelativeWindow window;
    window.half_width_m = 1.0;
    window.half_angle_rad = M_PI;
    window.flat_prior = true;
    window.trim_m = c.trim;
    const CorrelativeResult r = correlativeSearch(grid, pts, prior, window);
    const double step = searchHeadingStep(grid, pts);
    const int k = static_cast<int>(std::ceil(window.half_angle_rad / step)),
              w = static_cast<int>(std::ceil(window.half_width_m / grid.resolution()));
    const auto cells = [&](double trim) { return static_cast<int>(std::lround(trim / grid.resolution())); };
    double best = -1e300;
    common::Pose2 best_pose;
    for (int a = -k; a <= k; ++a)
      for (int i = -w + cells(c.trim[0]); i <= w - cells(c.trim[1]); ++i)
        for (int j = -w + cells(c.trim[2]); j <= w - cells(c.trim[3]); ++j) {
          const common::Pose2 x{0.2 + i * grid.resolution(), 0.1 + j * grid.resolution(), a * step};
          const Eigen::Matrix2d R = Eigen::Rotation2Dd(x.phi).toRotationMatrix();
          double s = 0;
          for (const auto& p : pts) s += grid.score(R * p + Eigen::Vector2d(x.x, x.y));
          if (s > best) best = s, best_pose = x;
        }
    EXPECT_NEAR(r.scan_score, best, 1e-3);
    EXPECT_NEAR(r.score - r.scan_score, prior.logDensity(0.0), 1e-9);
    EXPECT_NEAR(r.pose.x, best_pose.x, 1e-9);
    EXPECT_NEAR(r.pose.y, best_pose.y, 1e-9);
    EXPECT_NEAR(common::wrapToPi(r.pose.phi - best_pose.phi), 0.0, 1e-9);
    // The scan was taken at (0.3, 0.2, 2.0), inside every window here: the search finds it,
    // heading included.
    EXPECT_NEAR(r.pose.x, 0.3, 0.15);
    EXPECT_NEAR(r.pose.y, 0.2, 0.15);
    EXPECT_NEAR(common::wrapToPi(r.pose.phi - 2.0), 0.0, 0.05);
  }
}

// The scan taken at `truth` (in the reference scan's frame), matched from a prior at `odometry`.
PriorMatchResult matchRoom(const test::World& world, const common::Pose2& truth, const common::Pose2& odometry,
                           const Eigen::Matrix3d& cov) {
  const PriorMatcherOptions o;
  const MatchReference ref(scanPoints(world, {0, 0, 0}), Eigen::Vector2d::Zero(), o);
  return matchWithPrior(ref, scanPoints(world, truth, 11), odometry, cov, o);
}

TEST(PriorScanMatcher, GoodOdometryIsRefinedToTheTruth) {
  const common::Pose2 truth{0.45, 0.1, 0.05};
  const auto r = matchRoom(test::roomWorld(), truth, {0.5, 0.08, 0.06}, Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 1e-4).asDiagonal());
  ASSERT_TRUE(r.valid) << r.failure_reason;
  EXPECT_NEAR(r.pose.x, truth.x, 0.01);
  EXPECT_NEAR(r.pose.y, truth.y, 0.01);
  EXPECT_NEAR(r.pose.phi, truth.phi, 0.003);
  EXPECT_GT(r.prior_weight, 0.5);
}

TEST(PriorScanMatcher, SpreadIsTheSearchsDisagreementWithTheRefinement) {
  // Where the search and the refinement agree (to within the search's grid) the spread is as
  // small as that; it is always the second moment of the search's pose about the estimate.
  const common::Pose2 truth{0.45, 0.1, 0.05};
  const auto r = matchRoom(test::roomWorld(), truth, {0.5, 0.08, 0.06}, Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 1e-4).asDiagonal());
  ASSERT_TRUE(r.valid) << r.failure_reason;
  const Eigen::Vector3d d(r.search_pose.x - r.pose.x, r.search_pose.y - r.pose.y, common::wrapToPi(r.search_pose.phi - r.pose.phi));
  EXPECT_TRUE(r.spread.isApprox(d * d.transpose(), 1e-12) || d.norm() < 1e-12);
  const double cell = PriorMatcherOptions{}.grid.resolution_m;
  EXPECT_LE(std::sqrt(r.spread(0, 0) + r.spread(1, 1)), cell);
}

TEST(PriorScanMatcher, ClearScanMatchBeatsWrongOdometry) {
  // Reversing reported as driving forwards: the odometry says +0.5 m, the vehicle went -0.5 m;
  // and a missed 25° turn. The prior's covariance knows nothing of either.
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 1e-4).asDiagonal();
  for (const auto& [truth, odometry] : {std::pair<common::Pose2, common::Pose2>{{-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}},
                                        std::pair<common::Pose2, common::Pose2>{{0.3, 0.2, 0.45}, {0.3, 0.2, 0.02}}}) {
    const auto r = matchRoom(test::roomWorld(), truth, odometry, cov);
    ASSERT_TRUE(r.valid) << r.failure_reason;
    EXPECT_NEAR(r.pose.x, truth.x, 0.02);
    EXPECT_NEAR(r.pose.y, truth.y, 0.02);
    EXPECT_NEAR(r.pose.phi, truth.phi, 0.005);
    EXPECT_LT(r.prior_weight, 0.01);  // the odometry was outvoted, not averaged in
  }
}

TEST(PriorScanMatcher, ReversingSinceAnAnchorIsFoundWithinTheAnchorsReach) {
  // A scan between keyframes: the odometry says +0.5 m since the keyframe, an earlier scan was
  // matched at +0.4 m, and since then the vehicle reversed 0.1 m instead of going on 0.1 m. The
  // reach from the anchor (0.1 m to it plus 0.1 m of travel) finds it as the whole increment's
  // twice 0.5 m does, in a window a third as wide.
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 1e-4).asDiagonal();
  const common::Pose2 truth{0.3, 0.0, 0.0}, odometry{0.5, 0.0, 0.0};
  PriorMatcherOptions o;
  o.search_window_m = 0.3;
  const MatchReference ref(scanPoints(test::roomWorld(), {0, 0, 0}), Eigen::Vector2d::Zero(), o);
  const PointSet scan = scanPoints(test::roomWorld(), truth, 11);
  const PriorMatchResult whole = matchWithPrior(ref, scan, odometry, cov, o);
  o.direction_reach_m = 0.1 + 0.1;
  const PriorMatchResult chained = matchWithPrior(ref, scan, odometry, cov, o);
  for (const PriorMatchResult* r : {&whole, &chained}) {
    ASSERT_TRUE(r->valid) << r->failure_reason;
    EXPECT_NEAR(r->pose.x, truth.x, 0.02);
    EXPECT_NEAR(r->pose.y, truth.y, 0.02);
    EXPECT_NEAR(r->pose.phi, truth.phi, 0.005);
  }
  EXPECT_LT(chained.search_nodes, whole.search_nodes);
  // A reach that stops short of the truth cannot find it.
  o.direction_reach_m = 0.0;
  o.search_window_m = 0.1;
  const PriorMatchResult too_short = matchWithPrior(ref, scan, odometry, cov, o);
  EXPECT_GT(std::abs(too_short.search_pose.x - truth.x), 0.05);
}

TEST(PriorScanMatcher, CorridorKeepsTheOdometryAlongItsAxis) {
  // Nothing in a straight corridor says how far the vehicle went: the odometry decides along x
  // (with its own uncertainty), the walls decide y and the heading.
  const common::Pose2 truth{0.6, 0.1, 0.02}, odometry{0.45, 0.2, 0.0};
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 4e-4).asDiagonal();
  const auto r = matchRoom(test::corridorWorld(), truth, odometry, cov);
  ASSERT_TRUE(r.valid) << r.failure_reason;
  EXPECT_NEAR(r.pose.x, odometry.x, 0.01);
  EXPECT_NEAR(r.pose.y, truth.y, 0.01);
  EXPECT_NEAR(r.pose.phi, truth.phi, 0.003);
  EXPECT_NEAR(std::sqrt(r.cov(0, 0)), 0.05, 0.005);  // along the axis: the prior's sigma
  EXPECT_LT(std::sqrt(r.cov(1, 1)), 0.01);           // across: the walls'
}

TEST(PriorScanMatcher, ANarrowedHeadingWindowFindsTheSameMatchInsideItAndMissesBeyond) {
  // The prior's heading sigma is 0.1 rad (a 17° window each side); the narrowed window reaches a
  // third of that. A scan turned 0.03 rad from the odometry is the same match from both, for
  // fewer nodes; one turned 0.2 rad is found by the full window only, and the narrowed search's
  // best lies at its edge (what HeadingCorrections::doubts() takes for a reason to search again).
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 0.01).asDiagonal();
  PriorMatcherOptions o;
  o.search_window_deg = 2;
  const MatchReference ref(scanPoints(test::roomWorld(), {0, 0, 0}), Eigen::Vector2d::Zero(), o);
  const common::Pose2 odometry{0.3, 0.1, 0.0};
  PriorMatcherOptions narrowed = o;
  narrowed.heading_window_scale = 1.0 / 3;

  const common::Pose2 near_truth{0.32, 0.08, 0.03};
  const PointSet near_scan = scanPoints(test::roomWorld(), near_truth, 11);
  const PriorMatchResult full = matchWithPrior(ref, near_scan, odometry, cov, o);
  const PriorMatchResult first = matchWithPrior(ref, near_scan, odometry, cov, narrowed);
  ASSERT_TRUE(full.valid && first.valid);
  EXPECT_NEAR(full.pose.phi, near_truth.phi, 0.005);
  EXPECT_EQ(first.pose.x, full.pose.x);
  EXPECT_EQ(first.pose.y, full.pose.y);
  EXPECT_EQ(first.pose.phi, full.pose.phi);
  EXPECT_NEAR(full.search_half_angle_rad, 0.3, 1e-12);
  EXPECT_NEAR(first.search_half_angle_rad, 0.1, 1e-12);
  EXPECT_LT(first.search_nodes, full.search_nodes);

  const common::Pose2 far_truth{0.32, 0.08, 0.2};
  const PointSet far_scan = scanPoints(test::roomWorld(), far_truth, 11);
  const PriorMatchResult far_full = matchWithPrior(ref, far_scan, odometry, cov, o);
  const PriorMatchResult far_first = matchWithPrior(ref, far_scan, odometry, cov, narrowed);
  ASSERT_TRUE(far_full.valid);
  EXPECT_NEAR(far_full.pose.phi, far_truth.phi, 0.005);
  EXPECT_GT(std::abs(far_first.search_pose.phi - far_truth.phi), 0.05);
  EXPECT_GT(std::abs(far_first.search_pose.phi - odometry.phi), HeadingCorrections::kEdgeShare * far_first.search_half_angle_rad);
}

TEST(PriorScanMatcher, LeavingTheDirectionsReachOutSearchesTheOdometrysThreeSigmaOnly) {
  // The same prior either way (the uniform share's density is that of the full window): a match
  // inside the narrower window is the same match, for fewer nodes; a reversal beyond it is not found.
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 1e-4).asDiagonal();
  PriorMatcherOptions o;
  o.search_window_m = 0.3;
  const MatchReference ref(scanPoints(test::roomWorld(), {0, 0, 0}), Eigen::Vector2d::Zero(), o);
  PriorMatcherOptions narrow = o;
  narrow.search_direction_reach = false;
  const common::Pose2 odometry{0.5, 0.0, 0.0};
  const PointSet near_scan = scanPoints(test::roomWorld(), {0.52, 0.03, 0.01}, 11);
  const PriorMatchResult full = matchWithPrior(ref, near_scan, odometry, cov, o);
  const PriorMatchResult first = matchWithPrior(ref, near_scan, odometry, cov, narrow);
  ASSERT_TRUE(full.valid && first.valid);
  EXPECT_EQ(first.pose.x, full.pose.x);
  EXPECT_EQ(first.pose.y, full.pose.y);
  EXPECT_EQ(first.pose.phi, full.pose.phi);
  EXPECT_NEAR(full.search_half_width_m, 1.0, 1e-12);  // twice the travel
  EXPECT_NEAR(first.search_half_width_m, 0.3, 1e-12);
  EXPECT_FALSE(full.window_narrowed);
  EXPECT_TRUE(first.window_narrowed);
  EXPECT_LT(first.search_nodes, full.search_nodes);
  const PointSet far_scan = scanPoints(test::roomWorld(), {-0.3, 0.0, 0.0}, 12);
  EXPECT_NEAR(matchWithPrior(ref, far_scan, odometry, cov, o).pose.x, -0.3, 0.02);
  EXPECT_GT(std::abs(matchWithPrior(ref, far_scan, odometry, cov, narrow).search_pose.x + 0.3), 0.5);
}

TEST(OdometryOutvotes, TrustedOnlyWhereMatchesRarelyOutvoteTheOdometry) {
  OdometryOutvotes fresh;
  EXPECT_FALSE(fresh.trusted());  // distrustful until matches have shown otherwise
  OdometryOutvotes clean;
  for (int k = 0; k < 80; ++k) clean.add(false);
  EXPECT_FALSE(clean.trusted());  // 1 in 100 with the prior
  clean.add(false);
  EXPECT_TRUE(clean.trusted());
  // One outvote in fifty (a robot that reverses now and then) is never trusted; one in a
  // thousand is, and stays so after each outvote.
  OdometryOutvotes often, rarely;
  for (int k = 1; k <= 5000; ++k) {
    often.add(k % 50 == 0);
    rarely.add(k % 1000 == 0);
    if (k > 500) {
      EXPECT_FALSE(often.trusted()) << k;
      EXPECT_TRUE(rarely.trusted()) << k;
    }
  }
  EXPECT_NEAR(often.rate(), 0.02, 0.005);
  OdometryOutvotes copy;
  copy.restore(often.outvotes(), often.matches());
  EXPECT_EQ(copy.rate(), often.rate());
}

// A match of the trusted odometry's window (0.4 m each way here; matches usually explain 80 %
// of the scan) is doubted at the window's outer quarter on either axis, when it outvoted the
// odometry, or below nine tenths of the usual share; otherwise it stands.
TEST(OdometryOutvotes, ANarrowedMatchIsDoubtedAtTheWindowsEdgeOrWhenItExplainsLittle) {
  const auto doubts = [](double dx, double dy, bool outvoted, double share) {
    return OdometryOutvotes::doubtsNarrowMatch(dx, dy, 0.4, outvoted, share, 0.8);
  };
  EXPECT_FALSE(doubts(0.0, 0.0, false, 0.8));
  EXPECT_FALSE(doubts(0.29, -0.29, false, 0.73));  // inside three quarters, 91 % of the usual
  EXPECT_TRUE(doubts(0.31, 0.0, false, 0.8));
  EXPECT_TRUE(doubts(0.0, -0.31, false, 0.8));
  EXPECT_TRUE(doubts(0.0, 0.0, true, 0.8));
  EXPECT_TRUE(doubts(0.0, 0.0, false, 0.71));                                         // 89 % of the usual
  EXPECT_FALSE(OdometryOutvotes::doubtsNarrowMatch(0.0, 0.0, 0.4, false, 0.1, 0.0));  // nothing usual yet
}

TEST(HeadingCorrections, TheWindowIsFiveRmsOfTheCorrectionsInTheModelsSigmas) {
  std::mt19937 rng(5);
  HeadingCorrections h;
  const double sigma = 0.08;  // the model's heading sigma of every match here [rad]
  std::normal_distribution<double> small(0, 0.2 * sigma), large(0, 1.5 * sigma), smaller(0, 0.05 * sigma);
  for (int k = 0; k < 49; ++k) h.add(small(rng), sigma, 0.9);
  EXPECT_EQ(h.windowScale(), 1.0);  // too few matches yet: the model's window
  for (int k = 0; k < 2000; ++k) h.add(small(rng), sigma, 0.9);
  EXPECT_NEAR(h.windowScale(), 5 * 0.2 / 3, 0.15 * 5 * 0.2 / 3);
  // Corrections as large as the model's sigma or more: never wider than the model's window.
  for (int k = 0; k < 2000; ++k) h.add(large(rng), sigma, 0.9);
  EXPECT_EQ(h.windowScale(), 1.0);
  // The memory follows better odometry.
  for (int k = 0; k < 2000; ++k) h.add(smaller(rng), sigma, 0.9);
  EXPECT_NEAR(h.windowScale(), 5 * 0.05 / 3, 0.2 * 5 * 0.05 / 3);
  // The state restored is the state saved.
  HeadingCorrections copy;
  copy.restore(h.sumSquares(), h.sumMatched(), h.matches());
  EXPECT_EQ(copy.windowScale(), h.windowScale());
}

TEST(HeadingCorrections, DoubtsAMatchAtTheWindowsEdgeOrExplainingLittleOfTheScan) {
  HeadingCorrections h;
  for (int k = 0; k < 100; ++k) h.add(0.001, 0.05, 0.8);
  const double half = 0.1;
  EXPECT_FALSE(h.doubts(true, 0.5 * half, half, 0.8));
  EXPECT_FALSE(h.doubts(true, -0.7 * half, half, 0.5));
  EXPECT_TRUE(h.doubts(true, 0.8 * half, half, 0.8));   // near the edge
  EXPECT_TRUE(h.doubts(true, -0.8 * half, half, 0.8));  // either side
  EXPECT_TRUE(h.doubts(true, 0.1 * half, half, 0.3));   // under half the usual 0.8 matched
  EXPECT_TRUE(h.doubts(false, 0.0, half, 0.8));         // no match at all
}

}  // namespace
}  // namespace urbanslam::alignment
