#pragma once
// The full planar pose of a level camera b from points known in 3D in camera a's frame and seen
// in b's image (perspective-n-point with three parameters): camera b sits at c = (-l, 0, f) in
// a's frame (f forward, l to the left: PlanarRelativePose.h's plane) turned by the heading change
// θ, so a point X_a is X_b = R_y(θ) (X_a - c) in b's frame (PlanarEpipolar.h's conventions:
// x right, y down, z forward) and projects to (X_b.x / X_b.z, X_b.y / X_b.z).
//
// The fit minimises the reprojection errors in normalised image coordinates, each whitened by
// its own covariance: the pixel noise plus the 3D point's uncertainty carried into b's image (a
// point triangulated from a short baseline is uncertain in depth, and its error is not the
// pixel noise). Levenberg-Marquardt, reweighted with a Cauchy loss (RANSAC's inliers still hold
// mismatches within its threshold); the covariance of (f, l, θ) is the first-order one,
// (Σ J' W J)⁻¹ with the weights the whitening gives.
#include <vector>

#include <Eigen/Core>

namespace urbanslam::vision_loop {

struct PlanarPnpPoint {
  Eigen::Vector3d x_a;                               // in camera a's frame
  Eigen::Matrix3d cov_a = Eigen::Matrix3d::Zero();   // of x_a
  Eigen::Vector2d seen_b = Eigen::Vector2d::Zero();  // normalised image coordinates in b
};

// X_b's normalised projection for the pose p = (f, l, θ), and its derivative with respect to p
// (d_pose, 2 x 3) and to x_a (d_point, 2 x 3). False when the point is not in front of camera b.
bool planarProjection(const Eigen::Vector3d& p, const Eigen::Vector3d& x_a, Eigen::Vector2d* projection,
                      Eigen::Matrix<double, 2, 3>* d_pose = nullptr, Eigen::Matrix<double, 2, 3>* d_point = nullptr);

struct PlanarPnpFit {
  bool converged = false;
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  // (f, l, θ)
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  double rms_whitened = 0;  // the whitened residuals' root mean square (1 for a consistent fit)
  int iterations = 0;
};

// The robust fit from `start`. `pixel_sigma`: the image noise in normalised units.
PlanarPnpFit fitPlanarPnp(const std::vector<PlanarPnpPoint>& points, const Eigen::Vector3d& start, double pixel_sigma,
                          int max_iterations = 50);

}  // namespace urbanslam::vision_loop
