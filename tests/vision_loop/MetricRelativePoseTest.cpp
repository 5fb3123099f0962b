// The full planar relative pose of two images, with a second image of the first place giving the
// depths: the planar perspective-n-point model against numerical derivatives and exact
// projections, its covariance against the spread of noisy fits, and the whole chain (matching,
// motion stereo, RANSAC, fit) on synthetic features of a known scene.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/LU>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/vision_loop/MetricRelativePose.h"
#include "urbanslam/vision_loop/PlanarPnp.h"

namespace urbanslam::vision_loop {
namespace {

// A facade-like scene in front of camera a: points 8-25 m deep, spread across and up and down.
std::vector<Eigen::Vector3d> scene(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> across(-12, 12), up(-3, 1.5), depth(8, 25);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(across(rng), up(rng), depth(rng));
  return pts;
}

TEST(PlanarPnp, JacobiansMatchNumericalDerivatives) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d p(2 * u(rng), 2 * u(rng), 0.3 * u(rng));
    const Eigen::Vector3d x(6 * u(rng), 2 * u(rng), 15 + 5 * u(rng));
    Eigen::Vector2d proj;
    Eigen::Matrix<double, 2, 3> jp, jx;
    ASSERT_TRUE(planarProjection(p, x, &proj, &jp, &jx));
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector2d plus, minus;
      Eigen::Vector3d dp = Eigen::Vector3d::Zero();
      dp(k) = h;
      ASSERT_TRUE(planarProjection(p + dp, x, &plus));
      ASSERT_TRUE(planarProjection(p - dp, x, &minus));
      EXPECT_LT(((plus - minus) / (2 * h) - jp.col(k)).norm(), 1e-7) << "pose parameter " << k;
      ASSERT_TRUE(planarProjection(p, x + dp, &plus));
      ASSERT_TRUE(planarProjection(p, x - dp, &minus));
      EXPECT_LT(((plus - minus) / (2 * h) - jx.col(k)).norm(), 1e-7) << "point coordinate " << k;
    }
  }
}

TEST(PlanarPnp, RecoversThePoseAndItsCovarianceIsTheSpreadOfNoisyFits) {
  std::mt19937 rng(5);
  const Eigen::Vector3d truth(1.7, -2.4, 0.12);  // 1.7 m forward, 2.4 m to the right, turned left
  const auto pts = scene(rng, 60);
  std::vector<PlanarPnpPoint> exact;
  for (const auto& x : pts) {
    Eigen::Vector2d proj;
    ASSERT_TRUE(planarProjection(truth, x, &proj));
    exact.push_back({x, Eigen::Matrix3d::Zero(), proj});
  }
  const PlanarPnpFit clean = fitPlanarPnp(exact, truth + Eigen::Vector3d(0.5, 0.4, -0.05), 1e-3);
  ASSERT_TRUE(clean.converged);
  EXPECT_LT((clean.pose - truth).norm(), 1e-8);

  // Pixel noise and uncertain depths, drawn as their covariances say: the mean NEES of the fit
  // against the truth is 3 when its covariance is the spread of its estimates.
  const double pixel = 0.5 / 500;  // half a pixel at f = 500
  std::normal_distribution<double> g(0, 1);
  double nees = 0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    std::vector<PlanarPnpPoint> noisy;
    for (const auto& x : pts) {
      // Depth uncertain along the ray (0.2 m at 10 m, growing with the square of the depth).
      const double sd = 0.2 * (x.z() / 10) * (x.z() / 10);
      const Eigen::Vector3d ray = x.normalized();
      const Eigen::Vector3d moved = x + sd * g(rng) * ray;
      Eigen::Vector2d proj;
      ASSERT_TRUE(planarProjection(truth, x, &proj));
      noisy.push_back({moved, sd * sd * ray * ray.transpose(), proj + pixel * Eigen::Vector2d(g(rng), g(rng))});
    }
    const PlanarPnpFit f = fitPlanarPnp(noisy, truth + Eigen::Vector3d(0.3, -0.2, 0.02), pixel);
    ASSERT_TRUE(f.converged);
    const Eigen::Vector3d d = f.pose - truth;
    nees += d.dot(f.cov.inverse() * d) / trials;
  }
  EXPECT_GT(nees, 2.4);
  EXPECT_LT(nees, 3.6);
}

// Features of a known scene seen by three level cameras: random binary descriptors, one per scene
// point, so that matching finds exactly the shared points; the pixel positions are the projections.
ImageFeatures render(const std::vector<Eigen::Vector3d>& pts, const cv::Mat& descriptors, const Eigen::Vector3d& pose,
                     const PinholeCamera& k, std::mt19937& rng, double noise_px) {
  std::normal_distribution<double> g(0, noise_px);
  ImageFeatures f;
  f.image_size = cv::Size(640, 480);
  for (size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector2d n;
    if (!planarProjection(pose, pts[i], &n)) continue;
    const double u = k.fx * n.x() + k.cx + g(rng), v = k.fy * n.y() + k.cy + g(rng);
    if (u < 0 || u >= 640 || v < 0 || v >= 480) continue;
    f.keypoints.emplace_back(static_cast<float>(u), static_cast<float>(v), 8.f);
    f.descriptors.push_back(descriptors.row(static_cast<int>(i)));
  }
  return f;
}

TEST(MetricRelativePose, MotionStereoAndPnpGiveTheLengthOfTheTranslation) {
  std::mt19937 rng(11);
  const auto pts = scene(rng, 300);
  cv::Mat descriptors(static_cast<int>(pts.size()), 32, CV_8U);
  cv::randu(descriptors, 0, 256);
  const PinholeCamera k;  // f = 500, 640 x 480
  // a2: 4 m along a's right (the vehicle drove on, the camera looks left) turned a little; b:
  // 1.5 m forward (towards the facade) and 2 m to the right, turned 0.1 rad.
  const Eigen::Vector3d a2(0.0, -4.0, -0.02), b(1.5, -2.0, 0.1);
  const ImageFeatures fa = render(pts, descriptors, Eigen::Vector3d::Zero(), k, rng, 0.3);
  const ImageFeatures fa2 = render(pts, descriptors, a2, k, rng, 0.3);
  const ImageFeatures fb = render(pts, descriptors, b, k, rng, 0.3);
  for (const double scale : {1.0, 1.1}) {
    // The odometry's distance between a and a2, wrong by `scale`: every depth and so b's
    // position scale with it, the heading does not.
    const StereoPoints s = triangulateWithSecondImage(fa, fa2, DescriptorType::Orb, k, scale * 4.0, 0.02 * 4.0);
    ASSERT_GT(s.x.size(), 100u) << s.failure_reason;
    const MetricRelativePose r = metricRelativePose(s, fa, fb, DescriptorType::Orb, k);
    ASSERT_TRUE(r.valid) << r.failure_reason;
    EXPECT_NEAR(r.pose.x, scale * b(0), 0.05 * scale);
    EXPECT_NEAR(r.pose.y, scale * b(1), 0.05 * scale);
    EXPECT_NEAR(r.pose.phi, b(2), 0.005);
    // The covariance knows the baseline is 0.08 m uncertain (2 % of 4 m, 1.8 % of 4.4 m): at least
    // that share of the distance.
    const double along = std::hypot(r.pose.x, r.pose.y);
    const Eigen::Vector2d dir(r.pose.x / along, r.pose.y / along);
    EXPECT_GT(std::sqrt(dir.dot(r.cov.topLeftCorner<2, 2>() * dir)), 0.999 * 0.08 / (scale * 4.0) * along);
    if (scale == 1.0) {
      const Eigen::Vector3d d(r.pose.x - b(0), r.pose.y - b(1), r.pose.phi - b(2));
      EXPECT_LT(d.dot(r.cov.inverse() * d), 16.27) << "beyond the 99.9 % bound of its own covariance";
    }
  }
}

TEST(MetricRelativePose, TooFewPointsOrMatchesAreRefused) {
  std::mt19937 rng(13);
  const auto pts = scene(rng, 15);
  cv::Mat descriptors(static_cast<int>(pts.size()), 32, CV_8U);
  cv::randu(descriptors, 0, 256);
  const PinholeCamera k;
  const ImageFeatures fa = render(pts, descriptors, Eigen::Vector3d::Zero(), k, rng, 0.3);
  const ImageFeatures fa2 = render(pts, descriptors, Eigen::Vector3d(0, -4, 0), k, rng, 0.3);
  const StereoPoints s = triangulateWithSecondImage(fa, fa2, DescriptorType::Orb, k, 4.0, 0.08);
  EXPECT_TRUE(s.x.empty());
  EXPECT_FALSE(s.failure_reason.empty());
  const MetricRelativePose r = metricRelativePose(s, fa, fa, DescriptorType::Orb, k);
  EXPECT_FALSE(r.valid);
  EXPECT_FALSE(triangulateWithSecondImage(fa, fa2, DescriptorType::Orb, k, 0.0, 0.0).failure_reason.empty());
}

}  // namespace
}  // namespace urbanslam::vision_loop
