#pragma once
// The relative pose of two images of a calibrated, level camera on a ground vehicle, reduced to
// the plane: matched features -> essential matrix (five-point RANSAC, OpenCV) -> rotation and
// the direction of the translation -> the heading change and the bearing of the second camera
// seen from the first. A single camera cannot see the length of the translation; the filter
// takes that from the odometry (esdf/BearingHeading.h).
//
// The five-point RANSAC's inliers then fit the planar model itself (PlanarEpipolar.h: bearing
// and heading by robust Levenberg-Marquardt on the Sampson residuals): two parameters instead of
// the essential matrix's five, so the level camera's constraint is used, not only read off.
//
// The covariance of (bearing, heading) is estimated by resampling the inliers (bootstrap): the
// spread of the five-point estimates from resampled correspondence sets about the planar one,
// which follows the inliers' residuals and their layout in the image (few, clustered or distant
// points give a wide spread), and, as RANSAC runs again, a facade pattern that offers two
// consistent sets of matches. (The fit's own first-order covariance is consistent on Gaussian
// pixel noise but not there: PlanarEpipolarTest, bench/camera/RESULTS.md.)
#include <limits>
#include <string>

#include <Eigen/Core>

#include "urbanslam/vision_loop/FeatureExtractor.h"

namespace urbanslam::vision_loop {

struct PinholeCamera {
  double fx = 500, fy = 500, cx = 320, cy = 240;  // pixels
};

// How the covariance of (bearing, heading) is estimated (the pose is the planar fit in every case).
enum class PoseCovariance {
  FivePointBootstrap,  // spread of five-point RANSAC estimates of resampled inlier sets (RANSAC reruns)
  PlanarBootstrap,     // spread of planar fits to resampled inlier sets (no RANSAC reruns)
  FirstOrder,          // the planar fit's own σ² (J'WJ)⁻¹
};

struct PlanarRelativePoseOptions {
  double ratio = 0.8;                // Lowe's ratio test
  double ransac_threshold_px = 1.0;  // distance to the epipolar line of an inlier
  double ransac_confidence = 0.999;
  int min_inliers = 20;
  double min_residual_px = 0.1;  // floor on the residuals' robust standard deviation (the planar fit's weights)
  int bootstrap_samples = 40;    // resampled inlier sets for the covariance
  PoseCovariance covariance = PoseCovariance::FivePointBootstrap;
  // Added to the covariance of every method: the error the residuals do not show (how the
  // scene's texture and the rendering or lens place the features), one standard deviation each
  // of bearing and heading, independent of the pair. 0: none.
  double floor_bearing_rad = 0, floor_heading_rad = 0;
  unsigned seed = 1;  // of the resampling (the result is reproducible)
};

struct PlanarRelativePose {
  bool valid = false;
  std::string failure_reason;
  double bearing_rad = 0;  // direction of camera b's position in camera a's frame (x forward, y left, counter-clockwise)
  double heading_rad = 0;  // heading of camera b minus heading of camera a (counter-clockwise)
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity();  // of (bearing, heading)
  // The inliers' depth in camera a per metre of baseline (their lower quartile: PlanarEpipolar.h,
  // sceneDepthPerBaseline): the same images taken b metres apart show a scene b times this deep.
  double depth_per_baseline = std::numeric_limits<double>::infinity();
  int matches = 0, inliers = 0;
};

// From pixel correspondences (point i of `a` and of `b` are one feature).
PlanarRelativePose planarRelativePose(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b, const PinholeCamera& camera,
                                      const PlanarRelativePoseOptions& options = {});
// From the two images' features (ratio-test matches first).
PlanarRelativePose planarRelativePose(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, const PinholeCamera& camera,
                                      const PlanarRelativePoseOptions& options = {});

}  // namespace urbanslam::vision_loop
