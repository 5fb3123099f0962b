// The planar epipolar model against projections of known scenes: the constraint holds for the
// true pose, the analytic Jacobian equals central differences, and the fit's first-order
// covariance is consistent with its errors over many noisy trials (mean NEES near 2).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "urbanslam/vision_loop/PlanarEpipolar.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"

using namespace urbanslam::vision_loop;

namespace {

// Points seen by both cameras of a level pair: camera b at `baseline_m` along bearing β in a's
// frame (x right, y down, z forward), turned by θ about the vertical (X_b = R_y(θ) (X_a - c)).
struct Pair {
  std::vector<Eigen::Vector2d> a, b;  // normalised image coordinates
  std::vector<double> depth_a;        // each point's depth along camera a's optical axis
};

Pair project(double bearing, double heading, double baseline_m, int points, double noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> ux(-12, 12), uy(-2, 2), uz(4, 30);
  std::normal_distribution<double> n(0, noise);
  const Eigen::Vector3d c = baseline_m * Eigen::Vector3d(-std::sin(bearing), 0, std::cos(bearing));
  Eigen::Matrix3d r;
  r << std::cos(heading), 0, std::sin(heading), 0, 1, 0, -std::sin(heading), 0, std::cos(heading);
  Pair p;
  while (static_cast<int>(p.a.size()) < points) {
    const Eigen::Vector3d xa(ux(rng), uy(rng), uz(rng));
    const Eigen::Vector3d xb = r * (xa - c);
    if (xb.z() < 1) continue;
    const Eigen::Vector2d ia(xa.x() / xa.z(), xa.y() / xa.z()), ib(xb.x() / xb.z(), xb.y() / xb.z());
    if (ia.cwiseAbs().maxCoeff() > 0.7 || ib.cwiseAbs().maxCoeff() > 0.7) continue;  // a 70° field of view
    p.a.push_back(ia + Eigen::Vector2d(n(rng), n(rng)));
    p.b.push_back(ib + Eigen::Vector2d(n(rng), n(rng)));
    p.depth_a.push_back(xa.z());
  }
  return p;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double lowerQuartile(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 4), v.end());
  return v[v.size() / 4];
}

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

TEST(PlanarEpipolar, TheTruePoseSatisfiesTheConstraint) {
  std::mt19937 rng(3);
  for (const auto& [bearing, heading] : {std::pair{0.0, 0.0}, {0.4, -0.2}, {-1.2, 0.5}, {2.8, 0.1}}) {
    const Pair p = project(bearing, heading, 2.0, 40, 0.0, rng);
    const Eigen::Matrix3d e = planarEssential(bearing, heading);
    for (size_t i = 0; i < p.a.size(); ++i) EXPECT_NEAR(sampsonResidual(e, p.a[i], p.b[i]), 0.0, 1e-12);
    // ... and a wrong one does not.
    const Eigen::Matrix3d wrong = planarEssential(bearing + 0.2, heading);
    double sum = 0;
    for (size_t i = 0; i < p.a.size(); ++i) sum += std::abs(sampsonResidual(wrong, p.a[i], p.b[i]));
    EXPECT_GT(sum / p.a.size(), 1e-3);
  }
}

TEST(PlanarEpipolar, AnalyticJacobianEqualsCentralDifferences) {
  std::mt19937 rng(5);
  const Pair p = project(0.7, -0.3, 1.5, 25, 0.002, rng);
  for (const auto& [bearing, heading] : {std::pair{0.7, -0.3}, {0.5, -0.1}, {-2.0, 1.0}}) {
    const Eigen::MatrixX2d j = sampsonJacobian(bearing, heading, p.a, p.b);
    const double h = 1e-6;
    for (size_t i = 0; i < p.a.size(); ++i) {
      const auto r = [&](double db, double dh) { return sampsonResidual(planarEssential(bearing + db, heading + dh), p.a[i], p.b[i]); };
      EXPECT_NEAR(j(static_cast<Eigen::Index>(i), 0), (r(h, 0) - r(-h, 0)) / (2 * h), 1e-6);
      EXPECT_NEAR(j(static_cast<Eigen::Index>(i), 1), (r(0, h) - r(0, -h)) / (2 * h), 1e-6);
    }
  }
}

// 400 noisy pairs (1 px at f = 500 on a 70° view; baselines 0.5-4 m; bearings all round; turns up
// to ±0.5 rad), each fitted from the truth displaced by a few degrees. Where camera b lies outside
// a's view (motion across the view, as a side-looking camera on a car sees it), the first-order
// covariance is consistent: mean NEES near 2, about 95 % within the 95 % bound. Where the epipole
// lies inside the view (motion along the optical axis), it is optimistic several times over.
TEST(PlanarEpipolar, FitIsAccurateAndItsCovarianceConsistentForMotionAcrossTheView) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ub(-M_PI, M_PI), uh(-0.5, 0.5), ul(0.5, 4.0), uguess(-0.05, 0.05);
  std::uniform_int_distribution<int> un(25, 120);
  const double noise = 1.0 / 500;
  double across_sum = 0, along_sum = 0;
  int across = 0, along = 0, within95 = 0;
  for (int k = 0; k < 400; ++k) {
    const double bearing = ub(rng), heading = uh(rng);
    const Pair p = project(bearing, heading, ul(rng), un(rng), noise, rng);
    const PlanarEpipolarFit fit = fitPlanarEpipolar(p.a, p.b, bearing + uguess(rng), heading + uguess(rng));
    ASSERT_TRUE(fit.converged);
    // The residual estimates the noise (a Sampson residual is about one noise sigma).
    EXPECT_LT(fit.rms_residual, 3 * noise);
    const Eigen::Vector2d d(wrap(fit.bearing_rad - bearing), wrap(fit.heading_rad - heading));
    const double nees = d.dot(fit.cov.inverse() * d);
    if (std::abs(std::tan(bearing)) > 0.7) {  // the epipole (x = -tan β) outside the ±0.7 view
      across_sum += nees;
      within95 += nees < 5.991;
      ++across;
    } else {
      along_sum += nees;
      ++along;
    }
  }
  ASSERT_GT(across, 150);
  ASSERT_GT(along, 100);
  EXPECT_GT(across_sum / across, 1.6);
  EXPECT_LT(across_sum / across, 3.0);
  EXPECT_GT(within95, across * 88 / 100);
  EXPECT_GT(along_sum / along, 4.0);
}

// The scene's depth per metre of baseline, times the true baseline, is the points' lower quartile of depth:
// exactly without noise, within a few per cent at a pixel of noise (f = 500) for motion across the
// view; a pair that shows no parallax is infinitely deep; no correspondence, likewise.
TEST(PlanarEpipolar, DepthPerBaselineTimesTheBaselineIsTheScenesDepth) {
  std::mt19937 rng(11);
  for (const auto& [bearing, heading, baseline] : {std::tuple{1.4, 0.1, 2.0}, {-1.5, -0.2, 0.7}, {0.9, 0.3, 4.0}}) {
    const Pair exact = project(bearing, heading, baseline, 61, 0.0, rng);
    const double truth = lowerQuartile(exact.depth_a);
    EXPECT_NEAR(baseline * sceneDepthPerBaseline(exact.a, exact.b, bearing, heading), truth, 1e-9 * truth);
    const Pair noisy = project(bearing, heading, baseline, 61, 0.002, rng);
    const double noisy_truth = lowerQuartile(noisy.depth_a);
    EXPECT_NEAR(baseline * sceneDepthPerBaseline(noisy.a, noisy.b, bearing, heading), noisy_truth, 0.1 * noisy_truth);
  }
  const Pair still = project(1.4, 0.0, 0.0, 20, 0.0, rng);  // the same place: no baseline at all
  EXPECT_TRUE(std::isinf(sceneDepthPerBaseline(still.a, still.b, 1.4, 0.0)));
  EXPECT_TRUE(std::isinf(sceneDepthPerBaseline({}, {}, 1.4, 0.0)));
}

TEST(PlanarEpipolar, TooFewPointsDoNotConverge) {
  std::mt19937 rng(1);
  const Pair p = project(0.3, 0.1, 2.0, 2, 0.0, rng);
  EXPECT_FALSE(fitPlanarEpipolar(p.a, p.b, 0.3, 0.1).converged);
}

TEST(PlanarRelativePose, EveryCovarianceMethodGivesThePlanarFitAndTheBootstrapSpreadsAsTheFirstOrderCovariance) {
  // Pixel correspondences of random scenes with 1 px Gaussian noise, the motion across the view
  // (where the first-order covariance is consistent, above): the pose is the planar fit whatever
  // the covariance method, and resampling the planar fit spreads each axis as the first-order
  // covariance says. (Its NEES is not asserted: bearing and heading are strongly correlated
  // here, and a 2x2 covariance from 100 resamples gets the narrow direction wrong often enough
  // to make the mean NEES several times 2.)
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ub(1.2, 1.9), uh(-0.2, 0.2);
  const PinholeCamera k;  // fx = fy = 500
  const double noise_px = 1.0;
  double sum_first = 0;
  std::vector<double> ratio_bearing, ratio_heading, depth_ratio;
  for (int trial = 0; trial < 60; ++trial) {
    const double bearing = ub(rng) * (trial % 2 ? 1 : -1), heading = uh(rng);
    const Pair p = project(bearing, heading, 2.0, 80, noise_px / k.fx, rng);
    std::vector<cv::Point2f> a, b;
    for (size_t i = 0; i < p.a.size(); ++i) {
      a.emplace_back(static_cast<float>(k.cx + k.fx * p.a[i].x()), static_cast<float>(k.cy + k.fy * p.a[i].y()));
      b.emplace_back(static_cast<float>(k.cx + k.fx * p.b[i].x()), static_cast<float>(k.cy + k.fy * p.b[i].y()));
    }
    PlanarRelativePoseOptions o;
    o.ransac_threshold_px = 3;
    o.covariance = PoseCovariance::PlanarBootstrap;
    o.bootstrap_samples = 100;
    const PlanarRelativePose boot = planarRelativePose(a, b, k, o);
    o.covariance = PoseCovariance::FirstOrder;
    const PlanarRelativePose first = planarRelativePose(a, b, k, o);
    ASSERT_TRUE(boot.valid && first.valid) << boot.failure_reason << " / " << first.failure_reason;
    EXPECT_EQ(boot.bearing_rad, first.bearing_rad);
    EXPECT_EQ(boot.heading_rad, first.heading_rad);
    // The scene's depth from the inliers, at the true 2 m baseline, where the pose is right (one
    // trial's RANSAC lands 2.4 rad off): within a factor of two on every pair, and right on the
    // median pair. (Bearing and heading errors that trade off against each other in the
    // epipolar constraint move every depth alike.)
    if (std::abs(wrap(first.bearing_rad - bearing)) < 0.1) {
      depth_ratio.push_back(2.0 * boot.depth_per_baseline / lowerQuartile(p.depth_a));
      EXPECT_GT(depth_ratio.back(), 0.5);
      EXPECT_LT(depth_ratio.back(), 2.0);
    }
    const Eigen::Vector2d d(wrap(first.bearing_rad - bearing), wrap(first.heading_rad - heading));
    sum_first += d.dot(first.cov.inverse() * d);
    ratio_bearing.push_back(boot.cov(0, 0) / first.cov(0, 0));
    ratio_heading.push_back(boot.cov(1, 1) / first.cov(1, 1));
  }
  EXPECT_GE(depth_ratio.size(), 55u);
  EXPECT_NEAR(median(depth_ratio), 1.0, 0.1);
  EXPECT_GT(sum_first / 60, 1.2);
  EXPECT_LT(sum_first / 60, 4.5);
  for (double r : {median(ratio_bearing), median(ratio_heading)}) {
    EXPECT_GT(r, 0.6);
    EXPECT_LT(r, 1.6);
  }
}

// The floors add their variances to the covariance of every method, and nothing to the pose.
TEST(PlanarRelativePose, FloorsAddTheirVariancesToEveryMethodsCovariance) {
  std::mt19937 rng(4);
  const PinholeCamera k;
  const Pair p = project(1.5, 0.1, 2.0, 80, 1.0 / k.fx, rng);
  std::vector<cv::Point2f> a, b;
  for (size_t i = 0; i < p.a.size(); ++i) {
    a.emplace_back(static_cast<float>(k.cx + k.fx * p.a[i].x()), static_cast<float>(k.cy + k.fy * p.a[i].y()));
    b.emplace_back(static_cast<float>(k.cx + k.fx * p.b[i].x()), static_cast<float>(k.cy + k.fy * p.b[i].y()));
  }
  for (const PoseCovariance method : {PoseCovariance::FirstOrder, PoseCovariance::PlanarBootstrap, PoseCovariance::FivePointBootstrap}) {
    PlanarRelativePoseOptions o;
    o.ransac_threshold_px = 3;
    o.covariance = method;
    const PlanarRelativePose plain = planarRelativePose(a, b, k, o);
    o.floor_bearing_rad = 0.02;
    o.floor_heading_rad = 0.005;
    const PlanarRelativePose floored = planarRelativePose(a, b, k, o);
    ASSERT_TRUE(plain.valid && floored.valid);
    EXPECT_EQ(floored.bearing_rad, plain.bearing_rad);
    EXPECT_EQ(floored.heading_rad, plain.heading_rad);
    const Eigen::Matrix2d added = floored.cov - plain.cov;
    EXPECT_NEAR(added(0, 0), 0.02 * 0.02, 1e-12);
    EXPECT_NEAR(added(1, 1), 0.005 * 0.005, 1e-12);
    EXPECT_NEAR(added(0, 1), 0.0, 1e-12);
  }
}
