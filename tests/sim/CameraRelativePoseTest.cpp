// The planar relative pose of two camera images (vision_loop/PlanarRelativePose.h) on simulated
// street views, against the renderer's true camera poses: bearing and heading errors, and whether
// the bootstrap covariance is honest (NEES of the 2-vector over the pairs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>
#include <cstdio>
#include <Eigen/LU>
#include <opencv2/core.hpp>

#include "StreetViews.h"
#include "urbanslam/sim/CameraRenderer.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"

namespace urbanslam::sim {
namespace {

cv::Mat toMat(const io::CameraImage& im) { return cv::Mat(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data())).clone(); }

TEST(PlanarRelativePose, StreetViewPairsMatchTheTruthWithinAnHonestCovariance) {
  const CityModel city(test::city1km());
  CameraOptions c;
  c.enabled = true;
  const CameraRenderer cam(c, city, 1);
  vision_loop::PinholeCamera k;
  k.fx = cam.fx();
  k.fy = cam.fy();
  k.cx = cam.cx();
  k.cy = cam.cy();
  const vision_loop::FeatureExtractor sift;
  int pairs = 0, valid = 0;
  double nees_sum = 0, worst_bearing = 0, worst_heading = 0;
  std::vector<double> bearing_errors, heading_errors;
  int within95 = 0;
  uint64_t index = 0;
  for (double t : {8.0, 20.0, 40.0, 60.0, 75.0, 90.0, 110.0, 130.0})
    for (double turn : {0.0, 0.12}) {
      const common::Pose2 a = test::streetView(city.streets(), t);
      const common::Pose2 b = common::compose(test::streetView(city.streets(), t, 1.5), {0, 0, turn});
      const auto fa = sift.extract(toMat(cam.render(index++, 0, a)));
      const auto fb = sift.extract(toMat(cam.render(index++, 0, b)));
      const auto r = vision_loop::planarRelativePose(fa, fb, sift.options().type, k);
      ++pairs;
      if (!r.valid) continue;
      ++valid;
      const common::Pose2 truth = common::between(a, b);
      const Eigen::Vector2d d(common::wrapToPi(r.bearing_rad - std::atan2(truth.y, truth.x)), common::wrapToPi(r.heading_rad - truth.phi));
      const double nees = d.dot(r.cov.inverse() * d);
      nees_sum += nees;
      within95 += nees < 5.991;
      bearing_errors.push_back(std::abs(d(0)));
      heading_errors.push_back(std::abs(d(1)));
      worst_bearing = std::max(worst_bearing, std::abs(d(0)));
      worst_heading = std::max(worst_heading, std::abs(d(1)));
      std::printf("[ info ] t %5.1f turn %.2f: %d inliers, bearing err %6.2f deg (sd %.2f), heading err %6.3f deg (sd %.3f), NEES %.2f\n",
                  t, turn, r.inliers, d(0) * 180 / M_PI, std::sqrt(r.cov(0, 0)) * 180 / M_PI, d(1) * 180 / M_PI,
                  std::sqrt(r.cov(1, 1)) * 180 / M_PI, nees);
    }
  ASSERT_GE(valid, pairs * 3 / 4);
  // Typical errors: the median pair (the covariance speaks for the others).
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(bearing_errors), 3 * M_PI / 180);
  EXPECT_LT(median(heading_errors), 0.5 * M_PI / 180);
  // Honest: never overconfident (a consistent 2-vector has mean NEES 2 and 95 % under 5.99); the
  // bootstrap errs on the wide side, but not by orders of magnitude.
  EXPECT_GE(within95, valid * 9 / 10);
  EXPECT_LT(nees_sum / valid, 3.0);
  EXPECT_GT(nees_sum / valid, 0.2);
  std::printf("[ info ] %d of %d pairs valid; mean NEES %.2f (2 if consistent), %d within the 95 %% bound; worst errors %.2f / %.3f deg\n",
              valid, pairs, nees_sum / valid, within95, worst_bearing * 180 / M_PI, worst_heading * 180 / M_PI);
}

}  // namespace
}  // namespace urbanslam::sim
