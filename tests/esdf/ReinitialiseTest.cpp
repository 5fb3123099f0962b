// Esdf::reinitialiseFromHeadings and committed heading branches against dense least squares
// written here from the edge list.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "TestUtil.h"
#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {
namespace {

struct Edge {
  int a, b;
  Vec3 z;  // heading: the committed branch
  Mat3 omega;
};

// A drive around 10 m squares with heading noise large enough that dead reckoning is far off
// after a lap, and closures back to the first lap; the closures' branches are those nearest
// the dead-reckoned estimate, as the filter commits them.
struct Drive {
  std::vector<Edge> edges;
  Esdf filter;
  Mat3 prior_cov = Vec3(1e-4, 2e-4, 1e-5).asDiagonal();
  std::vector<Vec3> truth;

  explicit Drive(unsigned seed) : filter(options()) {
    std::mt19937 rng(seed);
    // Correlated translation and heading errors: the positions' solve must keep the cross term.
    Mat3 cov;
    cov << 0.01, 0.002, 0.001, 0.002, 0.02, -0.002, 0.001, -0.002, 0.004;
    const Mat3 omega = cov.inverse();
    filter.initialise(Vec3(0.5, -0.3, 0.2), prior_cov);
    truth.assign(1, Vec3(0.5, -0.3, 0.2));
    for (int k = 1; k < 120; ++k) {
      const Vec3 step(1.0, 0.0, k % 10 == 0 ? M_PI / 2 : 0.0);
      truth.push_back(compose(truth.back(), step));
      const Vec3 z = step + Vec3(test::gauss(rng, 0.05), test::gauss(rng, 0.05), test::gauss(rng, 0.06));
      filter.augmentRelative(k - 1, z, omega);
      edges.push_back({k - 1, k, z, omega});
      if (k >= 45 && k % 7 == 0) {
        const int i = k % 40;
        const Vec3 zl = between(truth[i], truth[k]) + Vec3(test::gauss(rng, 0.05), test::gauss(rng, 0.05), test::gauss(rng, 0.02));
        Vec3 committed = zl;
        const double d = filter.mean(k).z() - filter.mean(i).z();
        committed.z() = d - common::wrapToPi(d - zl.z());
        filter.observeRelative(i, k, zl, omega);
        edges.push_back({i, k, committed, omega});
      }
    }
  }
  static EsdfOptions options() {
    EsdfOptions o;
    o.commit_heading_branch = true;
    return o;
  }
};

TEST(Reinitialise, HeadingsThenPositionsEqualDenseLeastSquares) {
  Drive d(7);
  const int n = d.filter.size();
  const Vec3 prior_mean = d.filter.mean(0);
  // A lap's dead reckoning must be far from consistent for this to test anything.
  double worst = 0;
  for (const Edge& e : d.edges)
    worst = std::max(worst, std::fabs(d.filter.mean(e.b).z() - d.filter.mean(e.a).z() - e.z.z()));
  ASSERT_GT(worst, 0.5);

  // Headings: min sum w (phi_b - phi_a - z_phi)^2 + prior, w = 1 / (Omega^-1)_phiphi.
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  h(0, 0) += 1.0 / d.prior_cov(2, 2);
  rhs(0) += prior_mean.z() / d.prior_cov(2, 2);
  for (const Edge& e : d.edges) {
    const double w = 1.0 / e.omega.inverse()(2, 2);
    h(e.a, e.a) += w;
    h(e.b, e.b) += w;
    h(e.a, e.b) -= w;
    h(e.b, e.a) -= w;
    rhs(e.b) += w * e.z.z();
    rhs(e.a) -= w * e.z.z();
  }
  const Eigen::VectorXd phi = h.ldlt().solve(rhs);

  // Positions with those headings: each edge's error [R(phi_a + z_phi)' (t_b - t_a) - Rz' z_t;
  // e_phi] is linear in t; minimise the whole weighted cost (cross terms included).
  Eigen::MatrixXd ht = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  Eigen::VectorXd gt = Eigen::VectorXd::Zero(2 * n);
  {
    const Mat3 w0 = d.prior_cov.inverse();
    ht.block<2, 2>(0, 0) += w0.topLeftCorner<2, 2>();
    // Prior error [t_0 - m_t; phi_0 - m_phi] = [t_0; e_phi] - [m_t; 0]
    gt.segment<2>(0) += w0.topLeftCorner<2, 2>() * prior_mean.head<2>() - w0.block<2, 1>(0, 2) * (phi(0) - prior_mean.z());
  }
  for (const Edge& e : d.edges) {
    const double c = std::cos(phi(e.a) + e.z.z()), s = std::sin(phi(e.a) + e.z.z());
    Eigen::Matrix2d rt;  // R(phi_a + z_phi)'
    rt << c, s, -s, c;
    const double cz = std::cos(e.z.z()), sz = std::sin(e.z.z());
    Eigen::Matrix2d rzt;
    rzt << cz, sz, -sz, cz;
    const Eigen::Vector2d k0 = -rzt * e.z.head<2>();  // error = rt (t_b - t_a) + k0 in translation
    const double e_phi = phi(e.b) - phi(e.a) - e.z.z();
    // cost = [u; e_phi]' W [u; e_phi], u = rt (t_b - t_a) + k0.
    const Eigen::Matrix2d wtt = e.omega.topLeftCorner<2, 2>();
    const Eigen::Vector2d wtp = e.omega.block<2, 1>(0, 2);
    const Eigen::Matrix2d m = rt.transpose() * wtt * rt;
    const Eigen::Vector2d lin = rt.transpose() * (wtt * k0 + wtp * e_phi);
    ht.block<2, 2>(2 * e.b, 2 * e.b) += m;
    ht.block<2, 2>(2 * e.a, 2 * e.a) += m;
    ht.block<2, 2>(2 * e.a, 2 * e.b) -= m;
    ht.block<2, 2>(2 * e.b, 2 * e.a) -= m;
    gt.segment<2>(2 * e.b) -= lin;
    gt.segment<2>(2 * e.a) += lin;
  }
  const Eigen::VectorXd t = ht.ldlt().solve(gt);

  // Every factor away from the anchored start moves, and is relinearised.
  EXPECT_GT(d.filter.reinitialiseFromHeadings(), static_cast<long long>(d.filter.factorCount()) * 9 / 10);
  for (int p = 0; p < n; ++p) {
    EXPECT_NEAR(d.filter.mean(p).z(), phi(p), 1e-9) << "pose " << p;
    EXPECT_NEAR(d.filter.mean(p).x(), t(2 * p), 1e-7) << "pose " << p;
    EXPECT_NEAR(d.filter.mean(p).y(), t(2 * p + 1), 1e-7) << "pose " << p;
  }
}

// Dense Gauss-Newton over the drive's edges and prior (wrapped heading errors, as g2o), started
// at `x`; returns the cost at convergence.
double denseOptimum(const Drive& d, std::vector<Vec3> x, const Vec3& prior_mean) {
  const int n = static_cast<int>(x.size());
  const Mat3 w0 = d.prior_cov.inverse();
  auto cost = [&](const std::vector<Vec3>& y) {
    const Vec3 e0 = poseDifference(y[0], prior_mean);
    double c = e0.dot(w0 * e0);
    for (const Edge& e : d.edges) {
      const Vec3 r = relativePoseError(y[e.a], y[e.b], e.z);
      c += r.dot(e.omega * r);
    }
    return c;
  };
  double c = cost(x);
  for (int it = 0; it < 100; ++it) {
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * n);
    h.block<3, 3>(0, 0) += w0;
    g.segment<3>(0) += w0 * poseDifference(x[0], prior_mean);
    for (const Edge& e : d.edges) {
      Mat3 ja, jb;
      const Vec3 r = relativePoseError(x[e.a], x[e.b], e.z, &ja, &jb);
      h.block<3, 3>(3 * e.a, 3 * e.a) += ja.transpose() * e.omega * ja;
      h.block<3, 3>(3 * e.b, 3 * e.b) += jb.transpose() * e.omega * jb;
      h.block<3, 3>(3 * e.a, 3 * e.b) += ja.transpose() * e.omega * jb;
      h.block<3, 3>(3 * e.b, 3 * e.a) += jb.transpose() * e.omega * ja;
      g.segment<3>(3 * e.a) += ja.transpose() * e.omega * r;
      g.segment<3>(3 * e.b) += jb.transpose() * e.omega * r;
    }
    const Eigen::VectorXd dx = h.ldlt().solve(-g);
    for (int p = 0; p < n; ++p) x[p] += dx.segment<3>(3 * p);
    const double next = cost(x);
    if (std::fabs(c - next) <= 1e-13 * c) return next;
    c = next;
  }
  return c;
}

TEST(Reinitialise, ThenGaussNewtonReachesTheOptimumFromTheTruth) {
  // Dead reckoning far off (see above); headings first, then the filter's Gauss-Newton, must
  // end where dense Gauss-Newton started at the true poses ends.
  for (unsigned seed : {7u, 11u, 12u}) {
    Drive d(seed);
    const Vec3 prior_mean = d.filter.mean(0);
    const double reference = denseOptimum(d, d.truth, prior_mean);
    d.filter.reinitialiseFromHeadings();
    const RecoveryStats st = d.filter.recover();
    EXPECT_TRUE(st.converged);
    EXPECT_NEAR(d.filter.cost(), reference, 1e-6 * reference) << "seed " << seed;
  }
}

}  // namespace
}  // namespace urbanslam::esdf
