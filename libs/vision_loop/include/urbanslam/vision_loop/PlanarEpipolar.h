#pragma once
// The epipolar geometry of a level camera moving in the plane, with two parameters: the bearing
// β of camera b's position seen from camera a and the heading change θ (PlanarRelativePose.h's
// conventions; camera frame x right, y down, z forward). R = R_y(θ) maps a's coordinates to
// b's, b sits at c = (-sin β, 0, cos β) in a's frame (unit length: the scale is not seen), and
// E = [t]x R with t = -R c, so that x_b' E x_a = 0 for normalised image points.
//
// The fit minimises the Sampson residuals of the correspondences over (β, θ) (Hartley &
// Zisserman §11.4.3: the first-order geometric distance to the epipolar constraint) by
// Levenberg-Marquardt, reweighted with a Cauchy loss whose scale comes from the residuals' median
// absolute deviation (RANSAC's inliers still hold mismatches within its threshold). Its
// covariance is the first-order one, σ² (J'WJ)⁻¹, with the pixel noise σ estimated from the
// residuals. With two parameters instead of the essential matrix's five, the level camera's
// constraint is used, not only read off.
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace urbanslam::vision_loop {

// E(β, θ) as above.
Eigen::Matrix3d planarEssential(double bearing_rad, double heading_rad);

// Sampson residual of one correspondence (normalised image coordinates, z = 1), in the units of
// the normalised image plane: multiply by the focal length for pixels.
double sampsonResidual(const Eigen::Matrix3d& e, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb);

// d r / d(β, θ) of every correspondence's Sampson residual, analytic (rows: correspondences).
Eigen::MatrixX2d sampsonJacobian(double bearing_rad, double heading_rad, const std::vector<Eigen::Vector2d>& a,
                                 const std::vector<Eigen::Vector2d>& b);

struct PlanarEpipolarFit {
  bool converged = false;
  double bearing_rad = 0, heading_rad = 0;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity();  // of (bearing, heading)
  double rms_residual = 0;                            // normalised image units
  int iterations = 0;
};

// The robust fit from (bearing, heading) over the correspondences a[i] <-> b[i] (normalised image
// coordinates; at least three). `min_sigma`: a floor on the residuals' robust standard deviation
// (normalised units), so that a perfect fit of few points does not claim exactness.
PlanarEpipolarFit fitPlanarEpipolar(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double bearing_rad,
                                    double heading_rad, double min_sigma = 0, int max_iterations = 50);

// Where the ray of camera a through xa and the ray of camera b through xb (normalised image
// coordinates) come closest, b sitting at `baseline` along (β, θ) as above: the two rays'
// parameters (X = depth_a (xa, 1) on a's ray, c + along_b R' (xb, 1) on b's), the midpoint of the
// two closest points and the angle between the rays, in a's frame. Nothing when the rays are
// parallel; a point behind a camera has a parameter of 0 or less.
struct RayMeeting {
  double depth_a = 0, along_b = 0;
  Eigen::Vector3d midpoint = Eigen::Vector3d::Zero();
  double parallax_rad = 0;
};
std::optional<RayMeeting> meetRays(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb, double bearing_rad, double heading_rad,
                                   double baseline);

// How far the scene the two images share lies, per metre between the cameras: the lower quartile,
// over the correspondences, of the depth along camera a's optical axis at which the two rays meet
// (least squares) for a unit baseline along (β, θ). A monocular pair fixes the scene only up to
// the baseline's length, so the depth at a baseline b is b times this. The nearer points have
// the most parallax: an error of the heading (which trades off against the bearing in the
// epipolar constraint) moves their depths least. A correspondence whose rays meet behind either
// camera, or do not converge, counts as infinitely far; infinity for no correspondence.
double sceneDepthPerBaseline(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double bearing_rad,
                             double heading_rad);

}  // namespace urbanslam::vision_loop
