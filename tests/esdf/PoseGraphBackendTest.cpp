// The incremental back end against a dense batch Gauss-Newton optimum, the effect of
// relinearisation, and the benchmark graphs when present.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <filesystem>

#include "TestUtil.h"
#include "urbanslam/esdf/PoseGraphBackend.h"

namespace urbanslam::esdf {
namespace {

// A small city block tour: 4 x 4 blocks driven in loops, odometry with heading noise large
// enough to make the first linearisation visibly wrong, loop closures on revisits.
// With `truth_out`, also the true poses.
PoseGraph cityGraph(unsigned seed, int poses, double heading_sigma, std::vector<Vec3>* truth_out = nullptr) {
  std::mt19937 rng(seed);
  PoseGraph g;
  std::vector<Vec3> truth{Vec3::Zero()};
  const Mat3 odo_info = Vec3(100.0, 100.0, 1.0 / (heading_sigma * heading_sigma)).asDiagonal();
  const Mat3 loop_info = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  std::uniform_int_distribution<int> coin(0, 2);
  for (int k = 1; k < poses; ++k) {
    // Turn at grid intersections (every 5 m), left or right or straight.
    double turn = 0;
    if (k % 5 == 0) turn = (coin(rng) - 1) * M_PI / 2;
    Vec3 next = compose(truth.back(), Vec3(1, 0, turn));
    // Stay within a 20 m x 20 m block grid: turn around at the border.
    if (std::abs(next.x()) > 20 || std::abs(next.y()) > 20) next = compose(truth.back(), Vec3(1, 0, M_PI));
    const Vec3 z = between(truth.back(), next);
    truth.push_back(next);
    g.edges.push_back({k - 1, k, z + Vec3(test::gauss(rng, 0.1), test::gauss(rng, 0.1), test::gauss(rng, heading_sigma)), odo_info});
    // Loop closures to earlier visits of the same spot.
    for (int j = 0; j + 10 < k; j += 1) {
      if ((truth[j].head<2>() - next.head<2>()).norm() < 0.5 && coin(rng) == 0) {
        const Vec3 zl = between(truth[j], next);
        g.edges.push_back({j, k, zl + Vec3(test::gauss(rng, 0.1), test::gauss(rng, 0.1), test::gauss(rng, 0.03)), loop_info});
        break;
      }
    }
  }
  if (truth_out) *truth_out = truth;
  return g;
}

// Dense Gauss-Newton on the whole graph (pose 0 fixed): the batch optimum for comparison.
double batchOptimumChi2(const PoseGraph& g, std::vector<Vec3> x) {
  const int n = static_cast<int>(x.size());
  std::vector<long> ids(n);
  for (int k = 0; k < n; ++k) ids[k] = k;
  double chi2 = poseGraphChi2(g, x, ids);
  for (int it = 0; it < 50; ++it) {
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(3 * n);
    for (const auto& e : g.edges) {
      const int i = static_cast<int>(e.from), j = static_cast<int>(e.to);
      const Vec3 r = relativePoseError(x[i], x[j], e.measurement);
      Mat3 ai, aj;
      relativePoseErrorJacobians(x[i], x[j], e.measurement, &ai, &aj);
      h.block<3, 3>(3 * i, 3 * i) += ai.transpose() * e.information * ai;
      h.block<3, 3>(3 * j, 3 * j) += aj.transpose() * e.information * aj;
      h.block<3, 3>(3 * i, 3 * j) += ai.transpose() * e.information * aj;
      h.block<3, 3>(3 * j, 3 * i) += aj.transpose() * e.information * ai;
      b.segment<3>(3 * i) -= ai.transpose() * e.information * r;
      b.segment<3>(3 * j) -= aj.transpose() * e.information * r;
    }
    h.block<3, 3>(0, 0) += Mat3::Identity() * 1e12;
    const Eigen::VectorXd dx = h.ldlt().solve(b);
    for (int k = 0; k < n; ++k) x[k] += dx.segment<3>(3 * k);
    const double next = poseGraphChi2(g, x, ids);
    if (std::abs(chi2 - next) < 1e-12 * chi2) return next;
    chi2 = next;
  }
  return chi2;
}

std::vector<Vec3> odometryChain(const PoseGraph& g, int n) {
  std::vector<Vec3> x(n, Vec3::Zero());
  for (const auto& e : g.edges)
    if (e.to == e.from + 1) x[e.to] = compose(x[e.from], e.measurement);
  return x;
}

TEST(PoseGraphBackend, ReachesTheBatchOptimumWithRelinearisation) {
  const PoseGraph g = cityGraph(50, 300, 0.02);
  const PoseGraphBackendResult r = runPoseGraphBackend(g);
  ASSERT_EQ(r.poses.size(), 300u);
  EXPECT_GT(r.observation_edges, 10);
  const double opt = batchOptimumChi2(g, r.poses);
  EXPECT_NEAR(r.chi2, opt, 1e-6 * opt) << "batch optimum " << opt;
  EXPECT_EQ(r.step_ms.size(), g.edges.size());
}

TEST(PoseGraphBackend, ReversedOdometryEdgesAndSparseIdsReachTheBatchOptimum) {
  // Every third odometry edge stored backwards (k -> k-1 with the inverse measurement), as some
  // files do; the back end must minimise the edges as given.
  PoseGraph g = cityGraph(53, 200, 0.03);
  for (size_t e = 0; e < g.edges.size(); e += 3) {
    auto& ed = g.edges[e];
    if (ed.to != ed.from + 1) continue;
    std::swap(ed.from, ed.to);
    ed.measurement = inverse(ed.measurement);
    ed.measurement.z() = common::wrapToPi(ed.measurement.z());
  }
  const PoseGraphBackendResult r = runPoseGraphBackend(g);
  const double opt = batchOptimumChi2(g, r.poses);
  EXPECT_NEAR(r.chi2, opt, 1e-6 * opt);
  // Vertex ids need not be contiguous: scaling them by 10 changes nothing.
  PoseGraph g10 = g;
  for (auto& ed : g10.edges) {
    ed.from *= 10;
    ed.to *= 10;
  }
  const PoseGraphBackendResult r10 = runPoseGraphBackend(g10);
  EXPECT_NEAR(r10.chi2, r.chi2, 1e-9 * r.chi2);
  EXPECT_EQ(r10.vertex_ids[5], 50);
}

TEST(PoseGraphBackend, RelinearisationBeatsSingleLinearisationAfterLargeLoops) {
  // Heading noise of 0.1 rad per step: after a loop the odometry estimate is far from the
  // truth, so linearising once (the thesis filter) leaves a visibly worse chi2.
  const PoseGraph g = cityGraph(51, 300, 0.1);
  PoseGraphBackendOptions once;
  once.filter.relinearise = false;
  const auto r_once = runPoseGraphBackend(g, once);
  const auto r_relin = runPoseGraphBackend(g);
  const double opt = batchOptimumChi2(g, odometryChain(g, 300));
  std::printf("chi2: single linearisation %.3f, relinearised %.3f, batch optimum %.3f\n", r_once.chi2, r_relin.chi2, opt);
  EXPECT_NEAR(r_relin.chi2, opt, 1e-4 * opt);
  EXPECT_GT(r_once.chi2, 1.01 * r_relin.chi2);
}

TEST(PoseGraphBackend, FullRecoveriesForcedByLargeHeadingInnovationsKeepTheBatchOptimum) {
  // No amortised full recoveries (huge minimum gap) and 0.15 rad of heading noise per step:
  // older stretches go stale between the partial recoveries, and some closures arrive with
  // heading innovations above the 1 rad limit, which forces a full recovery before they are
  // linearised. (Where this matters, a wrong-branch linearisation, needs a large graph: see
  // the README's 3e5-pose numbers. Here it checks that the forced recoveries happen and that
  // the result is the batch optimum, found by dense Gauss-Newton started from the true poses.)
  std::vector<Vec3> truth;
  const PoseGraph g = cityGraph(54, 400, 0.15, &truth);
  PoseGraphBackendOptions o;
  o.full_recovery_min_gap_fraction = 1e9;
  const auto r = runPoseGraphBackend(g, o);
  const double opt = batchOptimumChi2(g, truth);
  std::printf("chi2 %.3f (%d forced full recoveries, %d full in all), batch optimum %.3f\n", r.chi2, r.heading_triggered_recoveries,
              r.full_recoveries, opt);
  EXPECT_GT(r.heading_triggered_recoveries, 0);
  EXPECT_EQ(r.full_recoveries, r.heading_triggered_recoveries + 1);  // + the final one
  EXPECT_NEAR(r.chi2, opt, 1e-6 * opt);
}

TEST(PoseGraphBackend, HeadingsFirstRecoveriesAvoidTheWorstWrongBranch) {
  // The same policy on a longer drive with 0.15 rad of heading noise per step. A closure that
  // arrives on a stale estimate, re-solved by Gauss-Newton steps from that estimate, lands on
  // the wrong heading branch: 2*pi twists over loops, a local minimum at four times the
  // optimum that Gauss-Newton from the true poses finds. Re-solved headings first, it ends
  // within a fifth of that optimum. (At this noise no policy always finds the optimum; on the
  // benchmark's 10^6-pose drive, with realistic noise, headings first does: libs/esdf/README.md.)
  std::vector<Vec3> truth;
  const PoseGraph g = cityGraph(63, 800, 0.15, &truth);
  const double opt = batchOptimumChi2(g, truth);
  PoseGraphBackendOptions o;
  o.full_recovery_min_gap_fraction = 1e9;
  const auto r = runPoseGraphBackend(g, o);
  PoseGraphBackendOptions steps = o;
  steps.reinitialise_from_headings = false;
  steps.filter.commit_heading_branch = false;
  const auto r_steps = runPoseGraphBackend(g, steps);
  std::printf("chi2 headings first %.3f, Gauss-Newton steps %.3f, optimum from the truth %.3f\n", r.chi2, r_steps.chi2, opt);
  EXPECT_GT(r.heading_triggered_recoveries, 0);
  EXPECT_LT(r.chi2, 1.2 * opt);
  EXPECT_GT(r_steps.chi2, 4 * opt);
}

TEST(PoseGraphBackend, GatingRejectsAFalseLoopClosure) {
  const PoseGraph truth_graph = cityGraph(52, 200, 0.02);
  PoseGraph g = truth_graph;
  // A false closure: pose 150 "recognised" at pose 20's place, 8 m off.
  g.edges.push_back({20, 150, Vec3(8.0, 3.0, 1.0), Vec3(100.0, 100.0, 1000.0).asDiagonal()});
  PoseGraphBackendOptions o;
  o.gate_loop_closures = true;
  const auto r = runPoseGraphBackend(g, o);
  EXPECT_GE(r.rejected_edges, 1);
  EXPECT_LE(r.rejected_edges, 2) << "true closures rejected";
  const auto r_ungated = runPoseGraphBackend(g);
  // Judged on the true edges only: the false closure distorts the ungated map.
  const double gated = poseGraphChi2(truth_graph, r.poses, r.vertex_ids);
  const double ungated = poseGraphChi2(truth_graph, r_ungated.poses, r_ungated.vertex_ids);
  const double reference = runPoseGraphBackend(truth_graph).chi2;
  EXPECT_NEAR(gated, reference, 1e-6 * reference);
  EXPECT_GT(ungated, 2 * gated);
}

TEST(PoseGraphBackend, ManhattanM3500WhenPresent) {
  const std::string path = std::string(URBANSLAM_SHARED_DATA_DIR) + "/pose_graphs_2d/se-sync/manhattan.g2o";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const PoseGraph g = readPoseGraph(path);
  const auto r = runPoseGraphBackend(g);
  EXPECT_EQ(r.poses.size(), 3500u);
  EXPECT_EQ(r.edges, 5453);
  const std::vector<Vec3> odo = odometryChain(g, 3500);
  std::vector<long> ids(3500);
  for (int k = 0; k < 3500; ++k) ids[k] = k;
  EXPECT_LT(r.chi2, 0.01 * poseGraphChi2(g, odo, ids));
  std::printf("manhattan chi2 %.4f in %.3f s (%d full, %d partial recoveries)\n", r.chi2, r.time_s, r.full_recoveries,
              r.partial_recoveries);
}

}  // namespace
}  // namespace urbanslam::esdf
