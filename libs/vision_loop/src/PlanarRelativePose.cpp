#include "urbanslam/vision_loop/PlanarRelativePose.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/vision_loop/GeometricVerification.h"
#include "urbanslam/vision_loop/PlanarEpipolar.h"

namespace urbanslam::vision_loop {

namespace {

// (bearing, heading) from OpenCV's (R, t), where a point X_a in camera a's frame is R X_a + t in
// camera b's (x right, y down, z forward). Camera b sits at -R't in a's frame and looks along R's
// third row; the plane is (z forward, -x left).
Eigen::Vector2d planar(const cv::Mat& R, const cv::Mat& t) {
  const cv::Mat c = -R.t() * t;
  const double bearing = std::atan2(-c.at<double>(0), c.at<double>(2));
  const double heading = std::atan2(-R.at<double>(2, 0), R.at<double>(2, 2));
  return {bearing, heading};
}

// The pose from correspondences; false when no essential matrix or pose is found.
bool estimate(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b, const cv::Mat& k, const PlanarRelativePoseOptions& o,
              Eigen::Vector2d* out, std::vector<uchar>* inliers) {
  std::vector<uchar> mask;
  const cv::Mat e = cv::findEssentialMat(a, b, k, cv::RANSAC, o.ransac_confidence, o.ransac_threshold_px, mask);
  if (e.rows != 3 || e.cols != 3) return false;  // several solutions stacked, or none
  cv::Mat R, t;
  if (cv::recoverPose(e, a, b, k, R, t, mask) <= 0) return false;
  *out = planar(R, t);
  if (inliers) *inliers = mask;
  return true;
}

}  // namespace

PlanarRelativePose planarRelativePose(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b, const PinholeCamera& camera,
                                      const PlanarRelativePoseOptions& o) {
  PlanarRelativePose r;
  r.matches = static_cast<int>(a.size());
  if (a.size() != b.size() || r.matches < std::max(5, o.min_inliers)) {
    r.failure_reason = "too few matches";
    return r;
  }
  const cv::Mat k = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  Eigen::Vector2d x;
  std::vector<uchar> mask;
  if (!estimate(a, b, k, o, &x, &mask)) {
    r.failure_reason = "no essential matrix";
    return r;
  }
  std::vector<cv::Point2f> ia, ib;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) ia.push_back(a[i]), ib.push_back(b[i]);
  r.inliers = static_cast<int>(ia.size());
  if (r.inliers < o.min_inliers) {
    r.failure_reason = "too few inliers";
    return r;
  }
  // The planar model fitted to the inliers, from RANSAC's pose (normalised image coordinates).
  std::vector<Eigen::Vector2d> na, nb;
  for (size_t i = 0; i < ia.size(); ++i) {
    na.emplace_back((ia[i].x - camera.cx) / camera.fx, (ia[i].y - camera.cy) / camera.fy);
    nb.emplace_back((ib[i].x - camera.cx) / camera.fx, (ib[i].y - camera.cy) / camera.fy);
  }
  const PlanarEpipolarFit fit = fitPlanarEpipolar(na, nb, x(0), x(1), o.min_residual_px / (0.5 * (camera.fx + camera.fy)));
  if (!fit.converged) {
    r.failure_reason = "planar fit failed";
    return r;
  }
  x = Eigen::Vector2d(fit.bearing_rad, fit.heading_rad);
  r.bearing_rad = x(0);
  r.heading_rad = x(1);
  r.depth_per_baseline = sceneDepthPerBaseline(na, nb, x(0), x(1));
  const Eigen::Matrix2d floor =
      Eigen::Vector2d(o.floor_bearing_rad * o.floor_bearing_rad, o.floor_heading_rad * o.floor_heading_rad).asDiagonal();
  if (o.covariance == PoseCovariance::FirstOrder) {
    r.cov = fit.cov + floor;
    r.valid = true;
    return r;
  }
  // Bootstrap over the inliers: the spread of the estimates of resampled sets about the planar
  // one. A resample on which RANSAC lands elsewhere (a flipped or degenerate solution) would
  // dominate a plain second moment: samples beyond three robust standard deviations (from the
  // median absolute deviation) on either axis are left out of it.
  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<size_t> pick(0, ia.size() - 1);
  std::vector<Eigen::Vector2d> deviations;
  const double min_sigma = o.min_residual_px / (0.5 * (camera.fx + camera.fy));
  for (int k_sample = 0; k_sample < o.bootstrap_samples; ++k_sample) {
    std::vector<size_t> idx(ia.size());
    for (size_t& j : idx) j = pick(rng);
    Eigen::Vector2d y;
    if (o.covariance == PoseCovariance::PlanarBootstrap) {
      std::vector<Eigen::Vector2d> sa, sb;
      for (size_t j : idx) sa.push_back(na[j]), sb.push_back(nb[j]);
      const PlanarEpipolarFit f = fitPlanarEpipolar(sa, sb, x(0), x(1), min_sigma);
      if (!f.converged) continue;
      y = Eigen::Vector2d(f.bearing_rad, f.heading_rad);
    } else {
      std::vector<cv::Point2f> sa, sb;
      for (size_t j : idx) sa.push_back(ia[j]), sb.push_back(ib[j]);
      if (!estimate(sa, sb, k, o, &y, nullptr)) continue;
    }
    deviations.emplace_back(common::wrapToPi(y(0) - x(0)), common::wrapToPi(y(1) - x(1)));
  }
  if (deviations.size() < 5) {
    r.failure_reason = "unstable under resampling";
    return r;
  }
  Eigen::Vector2d limit;
  for (int axis = 0; axis < 2; ++axis) {
    std::vector<double> v;
    for (const auto& d : deviations) v.push_back(d(axis));
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    const double median = v[v.size() / 2];
    for (double& e : v) e = std::abs(e - median);
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    limit(axis) = std::max(3 * 1.4826 * v[v.size() / 2], 1e-9);
  }
  Eigen::Matrix2d s = Eigen::Matrix2d::Zero();
  int n = 0;
  for (const auto& d : deviations) {
    if (std::abs(d(0)) > limit(0) || std::abs(d(1)) > limit(1)) continue;
    s += d * d.transpose();
    ++n;
  }
  if (n < 5) {
    r.failure_reason = "unstable under resampling";
    return r;
  }
  r.cov = s / n + floor;
  r.valid = true;
  return r;
}

PlanarRelativePose planarRelativePose(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, const PinholeCamera& camera,
                                      const PlanarRelativePoseOptions& o) {
  const PointMatches m = matchFeatures(a, b, type, o.ratio);
  return planarRelativePose(m.a, m.b, camera, o);
}

}  // namespace urbanslam::vision_loop
