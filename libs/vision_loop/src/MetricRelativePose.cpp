#include "urbanslam/vision_loop/MetricRelativePose.h"

#include <Eigen/Dense>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "urbanslam/vision_loop/GeometricVerification.h"
#include "urbanslam/vision_loop/PlanarEpipolar.h"
#include "urbanslam/vision_loop/PlanarPnp.h"

namespace urbanslam::vision_loop {

namespace {

Eigen::Vector2d normalised(const cv::Point2f& p, const PinholeCamera& k) { return {(p.x - k.cx) / k.fx, (p.y - k.cy) / k.fy}; }

// The point where the rays of a (through xa) and of a2 (through x2) come closest, in a's frame
// (PlanarEpipolar.h, meetRays). False when the rays are parallel or meet behind either camera.
bool intersect(const Eigen::Vector2d& xa, const Eigen::Vector2d& x2, double bearing, double heading, double baseline, Eigen::Vector3d* out,
               double* parallax = nullptr) {
  const auto meeting = meetRays(xa, x2, bearing, heading, baseline);
  if (!meeting || !(meeting->depth_a > 0 && meeting->along_b > 0)) return false;
  *out = meeting->midpoint;
  if (parallax) *parallax = meeting->parallax_rad;
  return true;
}

}  // namespace

StereoPoints triangulateWithSecondImage(const ImageFeatures& a, const ImageFeatures& a2, DescriptorType type, const PinholeCamera& camera,
                                        double baseline_m, double baseline_sigma_m, const MetricRelativePoseOptions& o) {
  StereoPoints s;
  s.baseline_m = baseline_m;
  s.baseline_sigma_m = baseline_sigma_m;
  if (!(baseline_m > 0)) {
    s.failure_reason = "no baseline";
    return s;
  }
  const PointMatches m = matchFeatures(a, a2, type, o.ratio);
  PlanarRelativePoseOptions po;
  po.ratio = o.ratio;
  po.min_inliers = o.min_points;
  po.covariance = PoseCovariance::FirstOrder;
  const PlanarRelativePose rel = planarRelativePose(m.a, m.b, camera, po);
  if (!rel.valid) {
    s.failure_reason = "second image: " + rel.failure_reason;
    return s;
  }
  const double f = 0.5 * (camera.fx + camera.fy), sigma = o.pixel_sigma_px / f;
  const Eigen::Matrix3d e = planarEssential(rel.bearing_rad, rel.heading_rad);
  s.bearing_rad = rel.bearing_rad;
  s.heading_rad = rel.heading_rad;
  s.direction_cov = rel.cov;
  for (size_t i = 0; i < m.a.size(); ++i) {
    const Eigen::Vector2d xa = normalised(m.a[i], camera), x2 = normalised(m.b[i], camera);
    if (std::abs(sampsonResidual(e, xa, x2)) * f > o.max_epipolar_px) continue;
    Eigen::Vector3d x;
    double parallax = 0;
    if (!intersect(xa, x2, rel.bearing_rad, rel.heading_rad, baseline_m, &x, &parallax) || parallax < o.min_parallax_deg * M_PI / 180)
      continue;
    // First order by central differences in the four image coordinates (the pixel noise).
    Eigen::Matrix<double, 3, 4> j;
    const double h = 1e-6;
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k) {
      Eigen::Vector4d v;
      v << xa, x2;
      Eigen::Vector3d plus, minus;
      v(k) += h;
      ok = intersect(v.head<2>(), v.tail<2>(), rel.bearing_rad, rel.heading_rad, baseline_m, &plus);
      v(k) -= 2 * h;
      ok = ok && intersect(v.head<2>(), v.tail<2>(), rel.bearing_rad, rel.heading_rad, baseline_m, &minus);
      j.col(k) = (plus - minus) / (2 * h);
    }
    if (!ok) continue;
    s.keypoint.push_back(m.ia[i]);
    s.x.push_back(x);
    s.cov.push_back(sigma * sigma * j * j.transpose());
    s.seen_a.push_back(xa);
    s.seen_a2.push_back(x2);
  }
  if (static_cast<int>(s.x.size()) < o.min_points) {
    s.failure_reason = "too few triangulated points";
    s.keypoint.clear(), s.x.clear(), s.cov.clear(), s.seen_a.clear(), s.seen_a2.clear();
  }
  return s;
}

MetricRelativePose metricRelativePose(const StereoPoints& stereo, const ImageFeatures& a, const ImageFeatures& b, DescriptorType type,
                                      const PinholeCamera& camera, const MetricRelativePoseOptions& o) {
  MetricRelativePose r;
  if (static_cast<int>(stereo.x.size()) < o.min_points) {
    r.failure_reason = stereo.failure_reason.empty() ? "too few triangulated points" : stereo.failure_reason;
    return r;
  }
  // a's features with a depth, matched in b.
  ImageFeatures with_depth;
  with_depth.image_size = a.image_size;
  for (int k : stereo.keypoint) {
    with_depth.keypoints.push_back(a.keypoints[static_cast<size_t>(k)]);
    with_depth.descriptors.push_back(a.descriptors.row(k));
  }
  const PointMatches m = matchFeatures(with_depth, b, type, o.ratio);
  r.matches = static_cast<int>(m.a.size());
  if (r.matches < o.min_points) {
    r.failure_reason = "too few matches";
    return r;
  }
  std::vector<cv::Point3f> object;
  for (int i : m.ia) {
    const Eigen::Vector3d& x = stereo.x[static_cast<size_t>(i)];
    object.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()), static_cast<float>(x.z()));
  }
  const cv::Mat k = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object, m.b, k, cv::noArray(), rvec, tvec, false, o.ransac_iterations, static_cast<float>(o.ransac_threshold_px),
                          o.ransac_confidence, inliers, cv::SOLVEPNP_EPNP) ||
      static_cast<int>(inliers.size()) < o.min_points) {
    r.failure_reason = "no perspective-n-point solution";
    return r;
  }
  // RANSAC's pose in the plane: b sits at -R't in a's frame, its heading from R's third row.
  cv::Mat rot;
  cv::Rodrigues(rvec, rot);
  const cv::Mat c = -rot.t() * tvec;
  const Eigen::Vector3d start(c.at<double>(2), -c.at<double>(0), std::atan2(-rot.at<double>(2, 0), rot.at<double>(2, 2)));
  std::vector<PlanarPnpPoint> points;
  std::vector<size_t> used;  // their stereo points
  for (int i : inliers) {
    const size_t s = static_cast<size_t>(m.ia[static_cast<size_t>(i)]);
    points.push_back({stereo.x[s], stereo.cov[s], normalised(m.b[static_cast<size_t>(i)], camera)});
    used.push_back(s);
  }
  r.inliers = static_cast<int>(points.size());
  const double pixel = o.pixel_sigma_px / (0.5 * (camera.fx + camera.fy));
  const PlanarPnpFit fit = fitPlanarPnp(points, start, pixel);
  if (!fit.converged) {
    r.failure_reason = "planar fit failed";
    return r;
  }
  // The a-a2 bearing and heading, each one standard deviation off: every point triangulated
  // again, the fit again from its pose; the pose's shift per unit is that column of dpose/d(β, θ).
  Eigen::Matrix<double, 3, 2> shared = Eigen::Matrix<double, 3, 2>::Zero();
  for (int k = 0; k < 2; ++k) {
    const double step = std::max(1e-5, std::sqrt(stereo.direction_cov(k, k)));
    const double bearing = stereo.bearing_rad + (k == 0 ? step : 0), heading = stereo.heading_rad + (k == 1 ? step : 0);
    std::vector<PlanarPnpPoint> moved = points;
    // A point whose rays no longer meet there keeps its position (intersect leaves it untouched).
    for (size_t i = 0; i < moved.size(); ++i)
      intersect(stereo.seen_a[used[i]], stereo.seen_a2[used[i]], bearing, heading, stereo.baseline_m, &moved[i].x_a);
    const PlanarPnpFit f = fitPlanarPnp(moved, fit.pose, pixel);
    if (!f.converged) {
      r.failure_reason = "unstable under the second image's direction";
      return r;
    }
    shared.col(k) = Eigen::Vector3d(f.pose(0) - fit.pose(0), f.pose(1) - fit.pose(1), common::wrapToPi(f.pose(2) - fit.pose(2))) / step;
  }
  r.pose = {fit.pose(0), fit.pose(1), fit.pose(2)};
  r.rms_whitened = fit.rms_whitened;
  // A baseline longer by a factor s places every point s times as far: b's position scales with
  // it, the heading does not.
  const Eigen::Vector3d scale_direction(fit.pose(0), fit.pose(1), 0.0);
  const double rel_sigma = stereo.baseline_sigma_m / stereo.baseline_m;
  r.cov =
      fit.cov + shared * stereo.direction_cov * shared.transpose() + rel_sigma * rel_sigma * scale_direction * scale_direction.transpose();
  r.cov.diagonal() +=
      Eigen::Vector3d(o.floor_forward_m * o.floor_forward_m, o.floor_left_m * o.floor_left_m, o.floor_heading_rad * o.floor_heading_rad);
  r.valid = r.cov.allFinite();
  if (!r.valid) r.failure_reason = "covariance is not finite";
  return r;
}

}  // namespace urbanslam::vision_loop
