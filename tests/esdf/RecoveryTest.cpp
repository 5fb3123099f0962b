// State and covariance recovery (CHOLMOD) against dense solves and a dense inverse.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <memory>
#include <tuple>

#include "TestUtil.h"
#include "urbanslam/esdf/EnvelopeCholesky.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/esdf/Recovery.h"

namespace urbanslam::esdf {
namespace {

const Mat3 kOdoInfo = Vec3(100.0, 100.0, 1000.0).asDiagonal();
const Mat3 kLoopInfo = Vec3(50.0, 50.0, 500.0).asDiagonal();

// A square-ish loop trajectory with noisy odometry and a few loop closures; no recovery yet.
void buildGraph(Esdf& f, std::mt19937& rng, int poses, int closures) {
  f.initialise(Vec3(0, 0, 0), Mat3::Identity() * 1e-6);
  for (int k = 1; k < poses; ++k) {
    const double turn = (k % 10 == 0) ? M_PI / 2 : 0.0;
    f.augmentRelative(k - 1, Vec3(1.0 + test::gauss(rng, 0.05), test::gauss(rng, 0.05), turn + test::gauss(rng, 0.01)), kOdoInfo);
  }
  std::uniform_int_distribution<int> pick(0, poses - 1);
  for (int c = 0; c < closures; ++c) {
    int i = pick(rng), j = pick(rng);
    if (std::abs(i - j) < 2) continue;
    const Vec3 z = between(f.mean(i), f.mean(j)) + Vec3(test::gauss(rng, 0.3), test::gauss(rng, 0.3), test::gauss(rng, 0.05));
    f.observeRelative(i, j, z, kLoopInfo);
  }
}

// buildGraph's graph in a filter that never relinearises, so its information form stays the
// linear system the dense references solve.
struct LinearGraph {
  LinearGraph(unsigned seed, int poses, int closures) : rng(seed), f(options()) { buildGraph(f, rng, poses, closures); }
  static EsdfOptions options() {
    EsdfOptions o;
    o.relinearise = false;
    return o;
  }
  std::mt19937 rng;
  Esdf f;
};

// A drive along parallel streets, each closed to the one before every few metres: a planar graph,
// as a city's, whose factor has small separators (a path solve touches a small part of it).
void streets(Esdf& f, int poses) {
  constexpr int kStreet = 100;
  for (int k = f.size(); k < poses; ++k) {
    const bool turn = k % kStreet == 0;
    f.augmentRelative(k - 1, turn ? Vec3(0, 1, M_PI) : Vec3(1, 0, 0), kOdoInfo);
    const int across = k - 2 * (k % kStreet) - 1;  // the pose beside it on the street before
    if (k % 2 == 0 && across >= 0 && across < k - 1) f.observeRelative(across, k, between(f.mean(across), f.mean(k)), kLoopInfo);
  }
}

Mat3 blk(const Eigen::MatrixXd& m, int i, int j) { return m.block<3, 3>(3 * i, 3 * j); }

TEST(Recovery, FullRecoveryEqualsDenseSolve) {
  LinearGraph g(30, 80, 10);
  Esdf& f = g.f;
  const Eigen::MatrixXd lambda = f.state().denseInformation();
  const Eigen::VectorXd mu_ref = lambda.ldlt().solve(f.state().denseEta());
  f.recover();
  EXPECT_LT((f.state().denseMean() - mu_ref).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Recovery, PartialRecoveryEqualsDenseConditionalSolve) {
  LinearGraph g(31, 60, 8);
  Esdf& f = g.f;
  const int first = 40, n = f.size();
  const Eigen::MatrixXd lambda = f.state().denseInformation();
  const Eigen::VectorXd eta = f.state().denseEta(), mu = f.state().denseMean();
  const int r = 3 * (n - first);
  const Eigen::VectorXd rhs = eta.tail(r) - lambda.bottomLeftCorner(r, 3 * first) * mu.head(3 * first);
  const Eigen::VectorXd ref = lambda.bottomRightCorner(r, r).ldlt().solve(rhs);
  f.recoverRecent(first);
  EXPECT_LT((f.state().denseMean().tail(r) - ref).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((f.state().denseMean().head(3 * first) - mu.head(3 * first)).norm(), 1e-15);  // older poses untouched
}

// The sparse inverse's diagonal blocks against the dense inverse, with both kinds of CHOLMOD
// factor: a loop with few closures factorises simplicially, many random closures fill it in
// enough for supernodes.
TEST(Recovery, InverseDiagonalBlocksEqualTheDenseInverse) {
  for (const auto& [poses, closures, supernodal] : {std::tuple{60, 3, false}, std::tuple{300, 400, true}}) {
    LinearGraph g(32, poses, closures);
    SparseCholesky chol;
    chol.factorize(g.f.state(), 0, g.f.size());
    ASSERT_EQ(chol.supernodal(), supernodal) << poses << " poses";
    const Eigen::MatrixXd sigma = g.f.state().denseInformation().inverse();
    const std::vector<Mat3> blocks = chol.inverseDiagonalBlocks();
    ASSERT_EQ(blocks.size(), static_cast<size_t>(g.f.size()));
    double worst = 0;
    for (int p = 0; p < g.f.size(); ++p)
      worst = std::max(worst, (blocks[static_cast<size_t>(p)] - blk(sigma, p, p)).cwiseAbs().maxCoeff() / blk(sigma, p, p).norm());
    EXPECT_LT(worst, 1e-9) << poses << " poses";
  }
}

// A simplicial factor is read in place by the sparse inverse (packed within its own arrays):
// the solves after it, and a factorisation reusing its analysis, are still those of the matrix.
TEST(Recovery, ASimplicialFactorReadByTheSparseInverseStillSolvesAndRefactorises) {
  LinearGraph g(33, 60, 3);
  const Eigen::MatrixXd lambda = g.f.state().denseInformation();
  const Eigen::MatrixXd sigma = lambda.inverse();
  std::mt19937 rng(7);
  Eigen::MatrixXd b(lambda.rows(), 2);
  for (int i = 0; i < b.size(); ++i) b(i) = test::gauss(rng, 1.0);
  const Eigen::MatrixXd x_ref = lambda.ldlt().solve(b);
  SparseCholesky chol;
  for (int round = 0; round < 2; ++round) {
    chol.factorize(g.f.state(), 0, g.f.size());
    ASSERT_FALSE(chol.supernodal());
    const std::vector<Mat3> blocks = chol.inverseDiagonalBlocks();
    double worst = 0;
    for (int p = 0; p < g.f.size(); ++p)
      worst = std::max(worst, (blocks[static_cast<size_t>(p)] - blk(sigma, p, p)).cwiseAbs().maxCoeff() / blk(sigma, p, p).norm());
    EXPECT_LT(worst, 1e-9) << "round " << round;
    EXPECT_LT((chol.solve(b) - x_ref).cwiseAbs().maxCoeff() / x_ref.cwiseAbs().maxCoeff(), 1e-9) << "round " << round;
  }
}

// Covariance blocks between chosen poses from their path solves against the dense inverse, with
// both kinds of factor; a path holds the pose's ancestors only, a small part of a large factor.
TEST(Recovery, PathSolvesGiveTheDenseInverseBetweenAnyTwoPoses) {
  for (const auto& [poses, closures, supernodal] : {std::tuple{60, 3, false}, std::tuple{300, 400, true}, std::tuple{2000, 0, true}}) {
    LinearGraph g(34, closures > 0 ? poses : 1, closures);
    if (closures == 0) streets(g.f, poses);
    SparseCholesky chol;
    chol.factorize(g.f.state(), 0, g.f.size());
    ASSERT_EQ(chol.supernodal(), supernodal) << poses << " poses";
    // The reference: the dense inverse, or for the large graph CHOLMOD's own column solves.
    const bool large = poses > 1000;
    const Eigen::MatrixXd sigma = large ? Eigen::MatrixXd() : g.f.state().denseInformation().inverse();
    const auto reference = [&](int a, int b) -> Mat3 {
      if (!large) return blk(sigma, a, b);
      Eigen::MatrixXd e = Eigen::MatrixXd::Zero(3 * poses, 3);
      e.block<3, 3>(3 * b, 0).setIdentity();
      return chol.solve(e).block<3, 3>(3 * a, 0);
    };
    std::mt19937 rng(9);
    std::uniform_int_distribution<int> pick(0, poses - 1);
    double worst = 0;
    long rows = 0;
    for (int t = 0; t < 40; ++t) {
      const int a = t == 0 ? 0 : pick(rng), b = t == 1 ? poses - 1 : pick(rng);
      const PathSolution pa = chol.pathSolve(a), pb = chol.pathSolve(b);
      rows += pa.begin.back();
      const Mat3 ref = reference(a, b), saa = reference(a, a);
      worst = std::max(worst, (SparseCholesky::covarianceBetween(pa, pb) - ref).cwiseAbs().maxCoeff() / saa.norm());
      EXPECT_LT((SparseCholesky::covarianceBetween(pb, pa) - ref.transpose()).cwiseAbs().maxCoeff(), 1e-9 * saa.norm());
    }
    EXPECT_LT(worst, 1e-9) << poses << " poses";
    if (poses == 2000) {
      EXPECT_LT(rows / 40, 3 * poses / 10) << "a path holds a tenth of the factor's rows or more";
    }
  }
  SparseCholesky none;
  EXPECT_THROW(none.pathSolve(0), std::logic_error);
  LinearGraph g(35, 20, 2);
  SparseCholesky chol;
  chol.factorize(g.f.state(), 0, g.f.size());
  EXPECT_THROW(chol.pathSolve(20), std::out_of_range);
}

// AMD's factor against METIS's: a factorisation that AMD's ordering makes dear is ordered by
// nested dissection when that takes fewer operations (our own count of the numeric
// factorisation, not CHOLMOD's estimate the choice uses), and the factor solves the same system.
// A city's streets (a planar graph) favour nested dissection; a chain with a few closures, AMD.
TEST(Recovery, ADearFactorisationIsOrderedByNestedDissectionWhereThatIsCheaper) {
  for (const bool city : {true, false}) {
    LinearGraph g(36, city ? 1 : 3000, city ? 0 : 6);
    if (city) streets(g.f, 6000);
    const InformationState& s = g.f.state();
    SparseCholesky amd(FillReducingOrdering::Amd), metis(FillReducingOrdering::Metis);
    amd.factorize(s, 0, g.f.size());
    metis.factorize(s, 0, g.f.size());
    ASSERT_FALSE(amd.nestedDissection());
    ASSERT_TRUE(metis.nestedDissection());
    const double wa = amd.factorisationWork(), wm = metis.factorisationWork();
    ASSERT_EQ(wm < wa, city) << "AMD " << wa << ", METIS " << wm << " multiply-adds";

    SparseCholesky chosen(FillReducingOrdering::Amd, 1.0), never(FillReducingOrdering::Amd, 1e30);
    chosen.factorize(s, 0, g.f.size());
    never.factorize(s, 0, g.f.size());
    EXPECT_EQ(chosen.nestedDissection(), city);
    EXPECT_EQ(chosen.factorisationWork(), std::min(wa, wm));
    EXPECT_EQ(chosen.factorNonZeros(), city ? metis.factorNonZeros() : amd.factorNonZeros());
    EXPECT_FALSE(never.nestedDissection());
    EXPECT_EQ(never.factorisationWork(), wa);

    std::mt19937 rng(10);
    Eigen::MatrixXd b(3 * g.f.size(), 2);
    for (int i = 0; i < b.size(); ++i) b(i) = test::gauss(rng, 1.0);
    const Eigen::MatrixXd x = chosen.solve(b), x_amd = amd.solve(b);
    EXPECT_LT((x - x_amd).cwiseAbs().maxCoeff() / x_amd.cwiseAbs().maxCoeff(), 1e-9);
    // A saved matrix factorised again chooses the same ordering: the same factor, bit for bit.
    SparseCholesky again(FillReducingOrdering::Amd, 1.0);
    again.factorize(chosen.matrix());
    EXPECT_EQ(again.nestedDissection(), city);
    EXPECT_EQ((again.solve(b) - x).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(Recovery, EnvelopeCholeskySolvesEveryWindowLikeDenseLlt) {
  // Windows with links leaving them (ignored), short in-window loops and, for first = 0, a link
  // from the newest to the oldest pose (the dense worst case of the envelope).
  LinearGraph g(33, 50, 15);
  Esdf& f = g.f;
  f.observeRelative(0, 49, between(f.mean(0), f.mean(49)), kLoopInfo);
  const Eigen::MatrixXd lambda = f.state().denseInformation();
  for (int first : {0, 1, 17, 35, 49}) {
    const int r = 3 * (f.size() - first);
    const Eigen::VectorXd b = Eigen::VectorXd::Random(r);
    EnvelopeCholesky env;
    env.factorize(f.state(), first, f.size());
    const Eigen::VectorXd ref = lambda.bottomRightCorner(r, r).llt().solve(b);
    EXPECT_LT((env.solve(b) - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff(), 1e-10) << "first " << first;
  }
  // The envelope from the dense matrix: row p holds blocks from its first non-zero one to p.
  size_t envelope = 0;
  for (int p = 0; p < f.size(); ++p) {
    int lo = 0;
    while (lo < p && blk(lambda, p, lo).cwiseAbs().maxCoeff() == 0) ++lo;
    envelope += static_cast<size_t>(p - lo + 1);
  }
  EnvelopeCholesky whole;
  whole.factorize(f.state(), 0, f.size());
  EXPECT_EQ(whole.storedBlocks(), envelope);
  EXPECT_GE(whole.storedBlocks(), 50u + 49u);  // row 49 reaches pose 0
}

TEST(Recovery, EnvelopeCholeskyRejectsAnUnanchoredWindow) {
  InformationState s;
  s.addPose(Vec3::Zero());
  s.addPose(Vec3::Zero());
  s.addDiagonal(0, Mat3::Identity());
  s.addDiagonal(1, Mat3::Identity());
  s.addBlock(0, 1, -Mat3::Identity());  // [I -I; -I I]: singular
  EnvelopeCholesky env;
  EXPECT_THROW(env.factorize(s, 0, 2), std::runtime_error);
  EXPECT_THROW(env.factorize(s, 1, 1), std::invalid_argument);
}

TEST(Recovery, MarginalsAndPairsEqualDenseInverse) {
  std::mt19937 rng(32);
  Esdf f;
  buildGraph(f, rng, 70, 12);
  f.recover();
  const Eigen::MatrixXd sigma = f.state().denseInformation().inverse();
  const double scale = sigma.cwiseAbs().maxCoeff();
  for (int i = 0; i < f.size(); i += 7) {
    EXPECT_LT((f.marginalCovariance(i) - blk(sigma, i, i)).cwiseAbs().maxCoeff() / scale, 1e-10);
    for (int j : {0, 13, f.size() - 1}) {
      if (i == j) continue;
      const Mat6 joint = f.jointCovariance(i, j);
      EXPECT_LT((joint.topLeftCorner<3, 3>() - blk(sigma, i, i)).cwiseAbs().maxCoeff() / scale, 1e-10);
      EXPECT_LT((joint.topRightCorner<3, 3>() - blk(sigma, i, j)).cwiseAbs().maxCoeff() / scale, 1e-10);
      EXPECT_LT((joint.bottomRightCorner<3, 3>() - blk(sigma, j, j)).cwiseAbs().maxCoeff() / scale, 1e-10);
    }
  }
}

template <int N>
double minEigen(const Eigen::Matrix<double, N, N>& m) { return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>>(m).eigenvalues().minCoeff(); }

// The conservative and the exact joint covariance of each pair: all conservative queries first,
// since an exact query refactorises and so refreshes the conservative one's reference.
std::vector<std::pair<Mat6, Mat6>> conservativeThenExact(Esdf& f, const std::vector<std::pair<int, int>>& pairs) {
  std::vector<std::pair<Mat6, Mat6>> out;
  for (auto [i, j] : pairs) out.push_back({f.jointCovariance(i, j, CovarianceMode::Conservative), Mat6::Zero()});
  for (size_t k = 0; k < pairs.size(); ++k) out[k].second = f.jointCovariance(pairs[k].first, pairs[k].second, CovarianceMode::Exact);
  return out;
}

TEST(Recovery, ConservativeCovarianceIsExactWithoutNewInformationAndAnUpperBoundWithIt) {
  LinearGraph g(33, 50, 6);
  Esdf& f = g.f;
  f.recover();  // factor of 50 poses
  // Dead reckoning beyond the factor: conservative is exact.
  for (int k = 50; k < 65; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  const auto exact = conservativeThenExact(f, {{3, 20}, {10, 60}, {55, 64}, {64, 2}});
  for (size_t k = 0; k < exact.size(); ++k) {
    const auto& [c, e] = exact[k];
    EXPECT_LT((c - e).cwiseAbs().maxCoeff() / e.cwiseAbs().maxCoeff(), 1e-9) << k;
  }
  f.recover();  // new factor at 65
  for (int k = 65; k < 80; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  // Loop closures after the factor add information: conservative >= exact (PSD difference).
  f.observeRelative(5, 79, between(f.mean(5), f.mean(79)), kLoopInfo);
  f.observeRelative(30, 70, between(f.mean(30), f.mean(70)), kLoopInfo);
  const auto bounded = conservativeThenExact(f, {{5, 79}, {30, 40}, {70, 78}, {12, 66}});
  for (size_t k = 0; k < bounded.size(); ++k) {
    const auto& [c, e] = bounded[k];
    EXPECT_GT(minEigen<6>(c - e), -1e-9 * e.norm()) << k;
    EXPECT_GT((c - e).norm(), 1e-6 * e.norm()) << "closures should make a difference for pair " << k;
  }
}

// Relative-pose covariance of (x_i, x_j) from their joint covariance, at the filter's means.
Mat3 relative(const Esdf& f, int i, int j, const Mat6& joint) { return betweenCovariance(f.mean(i), f.mean(j), joint); }

// The innovation gate's exact test refactorises a map that only gained closures and poses since
// the last factorisation: pose 7's conservative marginal before that factorisation (first), its
// exact marginal at it (second), and its conservative marginal after more closures (later).
struct GateFactorisation {
  explicit GateFactorisation(double keep_marginals_min_work) : f(options(keep_marginals_min_work)) {
    std::mt19937 rng(35);
    buildGraph(f, rng, 50, 6);
    f.recover();  // factor of 50 poses
    for (int k = 50; k < 65; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
    // Closures at more factored poses than the exact covariance updates the old factor for
    // (ExactUpdates.cpp): its next query refactorises.
    for (int i : {4, 12, 20, 28}) f.observeRelative(i, 64 - i / 4, between(f.mean(i), f.mean(64 - i / 4)), kLoopInfo);
    first = f.jointCovariance(7, 7, CovarianceMode::Conservative).topLeftCorner<3, 3>();
    const long long before = f.factorisations();
    exact_at_second = f.jointCovariance(7, 58, CovarianceMode::Exact);  // the gate's factorisation, at 65 poses
    refactorised = f.factorisations() == before + 1;
    second = exact_at_second.topLeftCorner<3, 3>();
    // Closures after it, into the new chain.
    for (int k = 65; k < 75; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
    f.observeRelative(8, 72, between(f.mean(8), f.mean(72)), kLoopInfo);
    later = f.jointCovariance(7, 7, CovarianceMode::Conservative).topLeftCorner<3, 3>();
  }
  static EsdfOptions options(double keep_marginals_min_work) {
    EsdfOptions o = LinearGraph::options();
    o.keep_marginals_min_work = keep_marginals_min_work;
    return o;
  }
  Esdf f;
  Mat3 first, second, later;
  Mat6 exact_at_second;
  bool refactorised = false;
};

TEST(Recovery, AFactorisationThatOnlyAddsInformationKeepsDearMarginalsAsUpperBounds) {
  // Kept however cheap (the case of a city of 10^6 keyframes, where they take minutes): the new
  // information can only shrink them, so they still bound the covariance from above. The poses
  // factored since are solved along their paths, exactly.
  GateFactorisation g(0);
  Esdf& f = g.f;
  ASSERT_TRUE(g.refactorised);
  EXPECT_LT((g.later - g.first).cwiseAbs().maxCoeff(), 1e-12 * g.first.norm()) << "the first factorisation's marginal is kept";
  EXPECT_GT((g.first - g.second).norm(), 1e-3 * g.second.norm()) << "the closures should have shrunk pose 7's marginal";
  // A pose factored by the second factorisation only: its marginal there, from its path solve.
  const Mat3 solved = f.jointCovariance(58, 58, CovarianceMode::Conservative).topLeftCorner<3, 3>();
  EXPECT_LT((solved - g.exact_at_second.bottomRightCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-9 * solved.norm());
  // Every kind of pair stays an upper bound of the exact covariance (the last queries: an exact
  // one refactorises).
  const std::vector<std::pair<int, int>> pairs{{7, 7}, {7, 58}, {7, 73}, {58, 74}, {2, 30}, {60, 60}};
  const auto bounded = conservativeThenExact(f, pairs);
  for (size_t k = 0; k < bounded.size(); ++k) {
    const auto& [c, e] = bounded[k];
    EXPECT_GT(minEigen<6>(c - e), -1e-9 * e.norm()) << k;
  }
}

TEST(Recovery, AFactorisationOfASmallMapComputesItsMarginalsAgain) {
  // With the default threshold a 65-pose map's sparse inverse is cheap: the marginals are those
  // of the new factorisation, tighter.
  GateFactorisation g(EsdfOptions{}.keep_marginals_min_work);
  ASSERT_TRUE(g.refactorised);
  EXPECT_LT((g.later - g.second).cwiseAbs().maxCoeff(), 1e-9 * g.second.norm());
}

TEST(Recovery, ARelinearisedFactorisationComputesTheMarginalsAgain) {
  // Relinearising changes Lambda, not only adds to it: the marginals of the factorisation before
  // bound nothing, and the conservative covariance is exact again, without new information.
  std::mt19937 rng(36);
  Esdf f;  // relinearises
  buildGraph(f, rng, 60, 8);
  f.recover();
  const Mat3 before = f.jointCovariance(5, 5, CovarianceMode::Conservative).topLeftCorner<3, 3>();
  // A closure that moves the map by decimetres, then a recovery as global SLAM runs it.
  f.observeRelative(5, 45, between(f.mean(5), f.mean(45)) + Vec3(0.4, -0.3, 0.1), kLoopInfo);
  f.recover();
  f.relinearise();
  f.recover(0);
  const auto pairs = conservativeThenExact(f, {{5, 5}, {5, 45}, {20, 59}});
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& [c, e] = pairs[k];
    EXPECT_LT((c - e).cwiseAbs().maxCoeff() / e.cwiseAbs().maxCoeff(), 1e-9) << k;
  }
  EXPECT_GT((before - pairs[0].second.topLeftCorner<3, 3>()).norm(), 1e-3 * before.norm()) << "the closure should change pose 5's marginal";
}

TEST(Recovery, ConservativeCovarianceAfterAClosureIsReachedThroughIt) {
  // Driving back along an earlier visit: after a closure from the factored map into the
  // dead-reckoned chain, a pose near the closure's earlier end is known relative to the newest
  // poses about as well as the exact covariance says, not as loosely as 40 steps of dead
  // reckoning from the factorisation would say. The bound stays an upper bound.
  LinearGraph g(34, 50, 6);
  Esdf& f = g.f;
  f.recover();  // factor of 50 poses
  for (int k = 50; k < 90; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  const Mat3 tight = Vec3(1e4, 1e4, 1e5).asDiagonal();
  f.observeRelative(10, 85, between(f.mean(10), f.mean(85)), tight);
  for (int k = 90; k < 93; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  const std::vector<std::pair<int, int>> pairs{{11, 92}, {92, 9}, {10, 85}, {30, 92}, {3, 60}, {92, 92}};
  std::vector<Mat6> cons;
  std::vector<Mat3> cons_relative;
  for (auto [i, j] : pairs) {
    cons.push_back(f.jointCovariance(i, j, CovarianceMode::Conservative));
    if (i != j) cons_relative.push_back(f.relativeCovariance(i, j, CovarianceMode::Conservative));
  }
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    const Mat6 e = f.jointCovariance(i, j, CovarianceMode::Exact);
    EXPECT_GT(minEigen<6>(cons[k] - e), -1e-9 * e.norm()) << k;
    if (i == j) {
      // The newest pose's own marginal through the closure: 40 steps of dead reckoning would
      // give far more.
      EXPECT_LT(cons[k](0, 0) + cons[k](1, 1), 3 * (e(0, 0) + e(1, 1))) << k;
      continue;
    }
    const Mat3 re = relative(f, i, j, e), rc = cons_relative[k];
    EXPECT_GT(minEigen<3>(rc - re), -1e-9 * re.norm()) << k;
    if (k < 3) {
      // Near the closure: the relative position's spread within 3x the exact one's (dead
      // reckoning from the factorisation gives 25x and 10^5x here).
      const double spread = rc(0, 0) + rc(1, 1), exact = re(0, 0) + re(1, 1);
      EXPECT_LT(spread, 3 * exact) << k << " ratio " << spread / exact;
    }
  }
}

TEST(Recovery, TheRelativeBoundThroughAClosureIsThatOfThePathsFactorsAlone) {
  // An earlier visit (poses 0..29) factorised, then a drive of 20 poses and a closure from pose
  // 20 of the earlier visit to the newest pose, and 5 more poses. The conservative relative
  // covariance of pose 14 and the newest pose is the exact one of a filter that holds only the
  // factors on the path 14 .. 20, the closure and the 5 poses after it, not a bound from the
  // whole map's solve.
  LinearGraph g(35, 30, 0);
  Esdf& f = g.f;
  f.recover();
  const Vec3 step(1, 0, 0.02);
  for (int k = 30; k < 50; ++k) f.augmentRelative(k - 1, step, kOdoInfo);
  const Mat3 tight = Vec3(1e4, 1e4, 1e5).asDiagonal();
  const Vec3 closure = between(f.mean(20), f.mean(49));
  f.observeRelative(20, 49, closure, tight);
  for (int k = 50; k < 55; ++k) f.augmentRelative(k - 1, step, kOdoInfo);
  const Mat3 bound = f.relativeCovariance(14, 54, CovarianceMode::Conservative);

  // The path alone: 14 -> 20 by the earlier visit's own factors, the closure, then the drive.
  Esdf path(LinearGraph::options());
  path.initialise(f.mean(14), Mat3::Identity() * 1e-9);
  for (int k = 15; k <= 20; ++k) path.augmentRelative(k - 15, between(f.mean(k - 1), f.mean(k)), kOdoInfo);
  path.augmentRelative(6, closure, tight);
  for (int k = 0; k < 5; ++k) path.augmentRelative(7 + k, step, kOdoInfo);
  const Mat3 reference = path.relativeCovariance(0, 12);
  EXPECT_LT((bound - reference).cwiseAbs().maxCoeff(), 1e-6 * reference.norm()) << bound << "\n\n" << reference;
  // And it bounds the whole map's exact relative covariance.
  EXPECT_GT(minEigen<3>(bound - f.relativeCovariance(14, 54)), -1e-9 * bound.norm());
}

TEST(Recovery, NotPositiveDefiniteThrows) {
  InformationState s;
  s.addPose(Vec3::Zero());
  s.addPose(Vec3::Zero());
  s.addDiagonal(0, Mat3::Identity());  // pose 1 has no information
  SparseCholesky chol;
  EXPECT_THROW(chol.factorize(s, 0, 2), std::runtime_error);
}

TEST(Recovery, AStoredFactorWithColumnPointersPastItsRowsIsRefusedBeforeAnyRead) {
  // One pose (3 columns) and 3 stored entries, but the first column claims entries 0..99: its
  // range must be refused before the rows are read, although the last pointer matches.
  SparseCholesky::Matrix m;
  m.first = 0;
  m.last = 1;
  m.colptr = {0, 100, 2, 3};
  m.rowind = {0, 1, 2};
  m.values = {1, 1, 1};
  SparseCholesky chol;
  EXPECT_THROW(chol.factorize(m), std::invalid_argument);
  m.colptr = {0, 1, 2, 3};  // the diagonal: a valid factor
  EXPECT_NO_THROW(chol.factorize(m));
  // Every column needs its diagonal (no entries at all, or a sub-diagonal entry first: refused
  // here, where CHOLMOD would fail on the empty pattern or factorise a singular matrix).
  m.colptr = {0, 0, 0, 0};
  m.rowind.clear();
  m.values.clear();
  EXPECT_THROW(chol.factorize(m), std::invalid_argument);
  m.colptr = {0, 2, 3, 4};
  m.rowind = {1, 2, 1, 2};
  m.values = {1, 1, 1, 1};
  EXPECT_THROW(chol.factorize(m), std::invalid_argument);
}

}  // namespace
}  // namespace urbanslam::esdf

namespace urbanslam::esdf {
namespace {

TEST(Relinearisation, MotionAndObservationFactorsConvergeToAStationaryPoint) {
  // Odometry-model predictions (isotropic translational Q_v, so Q does not depend on the
  // heading and the cost is a fixed function) with loop closures that disagree with the drift:
  // after recover() with relinearisation, the gradient of the total cost must vanish.
  std::mt19937 rng(34);
  Esdf f;
  const Mat3 p0 = Vec3(1e-4, 1e-4, 1e-5).asDiagonal();
  f.initialise(Vec3::Zero(), p0);
  auto odo = std::make_shared<OdometryModel>();
  const MatQ qv = MatQ(Eigen::Vector3d(0.01, 0.01, 0.004).asDiagonal());
  std::vector<Vec3> us, truth{Vec3::Zero()};
  for (int k = 1; k <= 40; ++k) {
    const Vec3 u_true(1.0, 0.0, k % 10 == 0 ? M_PI / 2 : 0.0);
    truth.push_back(compose(truth.back(), u_true));
    const Vec3 u = u_true + Vec3(test::gauss(rng, 0.1), test::gauss(rng, 0.1), test::gauss(rng, 0.06));
    us.push_back(u);
    f.predictAugment(odo, VecU(u), qv, 0);
  }
  const Mat3 om = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  struct Obs {
    int i, j;
    Vec3 z;
  };
  std::vector<Obs> obs;
  for (auto [i, j] : {std::pair{0, 40}, std::pair{5, 35}, std::pair{12, 28}})
    obs.push_back({i, j, between(truth[i], truth[j]) + Vec3(test::gauss(rng, 0.1), test::gauss(rng, 0.1), test::gauss(rng, 0.03))});
  for (const auto& o : obs) f.observeRelative(o.i, o.j, o.z, om);
  const RecoveryStats st = f.recover();
  EXPECT_TRUE(st.converged);
  EXPECT_GT(st.relinearise_passes, 0);

  const Mat3 wq = processInformation(MatU(Mat3::Identity()), qv, Vec3::Zero());  // J2 Q_v J2' = Q_v here
  auto cost = [&](const Eigen::VectorXd& x) {
    auto pose = [&](int k) -> Vec3 { return x.segment<3>(3 * k); };
    double c = poseDifference(pose(0), Vec3::Zero()).dot(p0.inverse() * poseDifference(pose(0), Vec3::Zero()));
    for (int k = 1; k <= 40; ++k) {
      const Vec3 e = poseDifference(pose(k), odo->predict(pose(k - 1), VecU(us[k - 1]), 0, nullptr, nullptr));
      c += e.dot(wq * e);
    }
    for (const auto& o : obs) {
      const Vec3 e = relativePoseError(pose(o.i), pose(o.j), o.z);
      c += e.dot(om * e);
    }
    return c;
  };
  const Eigen::VectorXd mu = f.state().denseMean();
  Eigen::VectorXd grad(mu.size());
  for (int k = 0; k < mu.size(); ++k) {
    Eigen::VectorXd a = mu, b = mu;
    a(k) += 1e-6;
    b(k) -= 1e-6;
    grad(k) = (cost(a) - cost(b)) / 2e-6;
  }
  // Compare with the gradient scale at the dead-reckoning start.
  const double c_opt = cost(mu);
  EXPECT_LT(grad.cwiseAbs().maxCoeff(), 1e-3) << "cost " << c_opt;
  // And the single-linearisation filter ends at a higher cost.
  EsdfOptions once_opt;
  once_opt.relinearise = false;
  Esdf once(once_opt);
  once.initialise(Vec3::Zero(), p0);
  for (const auto& u : us) once.predictAugment(odo, VecU(u), qv, 0);
  for (const auto& o : obs) once.observeRelative(o.i, o.j, o.z, om);
  once.recover();
  EXPECT_GT(cost(once.state().denseMean()), c_opt * 1.001);
}

}  // namespace
}  // namespace urbanslam::esdf

namespace urbanslam::esdf {
namespace {

TEST(Relinearisation, BacktrackingNeverIncreasesTheCostOnAnInconsistentGraph) {
  // Closures that contradict the odometry badly (wrong by metres and radians): undamped
  // Gauss-Newton oscillates here; the backtracking step keeps every recovery a descent.
  std::mt19937 rng(35);
  Esdf f;
  f.initialise(Vec3::Zero(), Mat3::Identity() * 1e-6);
  for (int k = 1; k <= 40; ++k) f.augmentRelative(k - 1, Vec3(1.0, 0.0, k % 10 == 0 ? M_PI / 2 : 0.0), Vec3(1.0, 1.0, 1.0).asDiagonal());
  double previous = f.cost();
  const Mat3 om = Mat3::Identity();
  for (auto [i, j, z] : {std::tuple{0, 40, Vec3(0, 0, 0)}, std::tuple{5, 35, Vec3(0, -5, -M_PI / 2)},
                         std::tuple{12, 28, Vec3(-2, -8, M_PI)}, std::tuple{3, 22, Vec3(4, 9, 2.5)}}) {
    f.observeRelative(i, j, z, om);
    const double with_new = f.cost();  // the new closure's error enters at the old mean
    f.recover(5);
    EXPECT_LE(f.cost(), with_new * (1 + 1e-9)) << "closure " << i << "-" << j;
    EXPECT_GE(with_new, previous - 1e-9);
    previous = f.cost();
  }
}

// A pose added from an older factored pose (a keyframe leaving mapped ground in a reduced pose
// graph) starts a lineage of the dead-reckoning chain from that pose. Conservative covariances
// stay exact without new information, across lineages too, and need no refactorisation; with a
// closure they stay upper bounds.
TEST(Recovery, AChainLineageFromAnOlderPoseKeepsTheConservativeCovarianceExact) {
  LinearGraph g(38, 50, 6);
  Esdf& f = g.f;
  f.recover();
  for (int k = 50; k < 56; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  f.augmentRelative(20, Vec3(0.5, 0.2, 0.1), kOdoInfo);  // pose 56, from factored pose 20
  for (int k = 57; k < 62; ++k) f.augmentRelative(k - 1, Vec3(1, 0, -0.05), kOdoInfo);
  const long long factorisations = f.factorisations();
  const std::vector<std::pair<int, int>> pairs{{56, 60}, {53, 61}, {10, 61}, {61, 61}, {58, 3}, {20, 57}, {55, 55}};
  for (auto [i, j] : pairs) f.jointCovariance(i, j, CovarianceMode::Conservative);
  EXPECT_EQ(f.factorisations(), factorisations);
  const auto exact = conservativeThenExact(f, pairs);
  for (size_t k = 0; k < exact.size(); ++k) {
    const auto& [c, e] = exact[k];
    EXPECT_LT((c - e).cwiseAbs().maxCoeff() / e.cwiseAbs().maxCoeff(), 1e-9) << k;
  }
  f.recover();
  for (int k = 62; k < 66; ++k) f.augmentRelative(k - 1, Vec3(1, 0, 0.05), kOdoInfo);
  f.augmentRelative(30, Vec3(0.5, 0.2, 0.1), kOdoInfo);  // pose 66
  f.augmentRelative(66, Vec3(1, 0, 0), kOdoInfo);
  f.observeRelative(40, 67, between(f.mean(40), f.mean(67)), kLoopInfo);
  f.observeRelative(5, 64, between(f.mean(5), f.mean(64)), kLoopInfo);
  const auto bounded = conservativeThenExact(f, {{66, 64}, {40, 67}, {12, 65}, {67, 67}});
  for (size_t k = 0; k < bounded.size(); ++k) {
    const auto& [c, e] = bounded[k];
    EXPECT_GT(minEigen<6>(c - e), -1e-9 * e.norm()) << k;
  }
}

// The factors on the tightest path between two poses bound their relative covariance: on a
// chain (no closure) the path holds all that is known about the pair, so the bound is the exact
// covariance; with closures it is an upper bound, tightest for poses a few factors apart.
TEST(Recovery, ThePathBoundIsExactOnAChainAndAnUpperBoundWithClosures) {
  LinearGraph chain(36, 40, 0);
  Mat3 path;
  for (auto [i, j] : std::vector<std::pair<int, int>>{{3, 9}, {25, 12}, {0, 39}}) {
    ASSERT_TRUE(chain.f.pathRelativeCovariance(i, j, &path));
    const Mat3 e = chain.f.relativeCovariance(i, j, CovarianceMode::Exact);
    EXPECT_LT((path - e).cwiseAbs().maxCoeff(), 1e-9 * e.norm()) << i << "," << j;
  }
  LinearGraph loops(37, 60, 8);
  for (auto [i, j] : std::vector<std::pair<int, int>>{{3, 5}, {20, 33}, {59, 1}}) {
    ASSERT_TRUE(loops.f.pathRelativeCovariance(i, j, &path));
    const Mat3 e = loops.f.relativeCovariance(i, j, CovarianceMode::Exact);
    EXPECT_GT(minEigen<3>(path - e), -1e-9 * e.norm()) << i << "," << j;
  }
  // Beyond the settled poses asked for, no bound (a new search: another pair).
  EXPECT_FALSE(chain.f.pathRelativeCovariance(1, 38, &path, 10));
  // The search from 38 goes on where it stopped when asked again.
  EXPECT_TRUE(chain.f.pathRelativeCovariance(1, 38, &path));
}

}  // namespace
}  // namespace urbanslam::esdf
