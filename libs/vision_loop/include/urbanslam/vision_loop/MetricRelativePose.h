#pragma once
// The full planar relative pose (forward, left, heading change) of two images of a level camera,
// with the translation's length: one image pair cannot see it (PlanarRelativePose.h), but the
// vehicle that took image a also took a second image a2 of the same place a known distance away
// (the odometry between them). Motion stereo places a's features in 3D from a and a2; their
// matches in image b then fix b's pose in a's frame, length included (perspective-n-point,
// reduced to the plane: PlanarPnp.h).
//
// Honest covariance: each 3D point carries its triangulation's covariance from the pixel noise,
// which the fit whitens each reprojection error with. The errors every point shares are carried
// as such, not averaged away over the points: the a-a2 bearing and heading (the points are
// triangulated again one standard deviation off, and the fit's pose moves by what their
// covariance then gives), and the baseline's length (a longer baseline scales every point, so
// the whole translation). And a floor per axis, for what none of these shows (calibrated like
// PlanarRelativePoseOptions' floors: bench/vision_loop).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"

namespace urbanslam::vision_loop {

struct MetricRelativePoseOptions {
  double ratio = 0.8;                // Lowe's ratio test, both pairs
  double pixel_sigma_px = 0.5;       // the features' position noise
  double max_epipolar_px = 1.0;      // a-a2 matches farther from the planar epipolar geometry are not triangulated
  double min_parallax_deg = 1.0;     // rays meeting at a smaller angle give no depth worth having
  int min_points = 20;               // triangulated points, and PnP inliers, at least
  double ransac_threshold_px = 2.0;  // PnP RANSAC's reprojection threshold
  double ransac_confidence = 0.999;
  int ransac_iterations = 300;
  double floor_forward_m = 0, floor_left_m = 0, floor_heading_rad = 0;  // added to the covariance (one sigma each)
};

// Camera a's features that a2 gives a depth: keypoint indices of a, their positions in a's frame
// (x right, y down, z forward) and covariances.
struct StereoPoints {
  std::vector<int> keypoint;
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Matrix3d> cov;              // from the pixel noise
  std::vector<Eigen::Vector2d> seen_a, seen_a2;  // normalised image coordinates the points come from
  double bearing_rad = 0, heading_rad = 0;       // of a2 seen from a
  Eigen::Matrix2d direction_cov = Eigen::Matrix2d::Zero();
  double baseline_m = 0, baseline_sigma_m = 0;
  std::string failure_reason;  // when empty of points
};

// From the features of a and a2 and the distance between the two cameras (with its standard
// deviation, from the odometry). The direction of the baseline and the heading change are the
// images' own (PlanarRelativePose).
StereoPoints triangulateWithSecondImage(const ImageFeatures& a, const ImageFeatures& a2, DescriptorType type, const PinholeCamera& camera,
                                        double baseline_m, double baseline_sigma_m, const MetricRelativePoseOptions& options = {});

struct MetricRelativePose {
  bool valid = false;
  std::string failure_reason;
  common::Pose2 pose;  // camera b in camera a's plane: x forward, y left, phi the heading change
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  int matches = 0, inliers = 0;
  double rms_whitened = 0;  // the fit's whitened residuals (PlanarPnpFit)
};

MetricRelativePose metricRelativePose(const StereoPoints& stereo, const ImageFeatures& a, const ImageFeatures& b, DescriptorType type,
                                      const PinholeCamera& camera, const MetricRelativePoseOptions& options = {});

}  // namespace urbanslam::vision_loop
