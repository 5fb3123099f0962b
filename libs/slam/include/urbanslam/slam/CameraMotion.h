#pragma once
// Local SLAM with a camera and no laser: the motion between two keyframes from the odometry,
// weighed against the camera's view of it (the planar relative pose of the two keyframes'
// images: the heading change and the direction of travel, not its length). Each is weighed by
// its covariance, as a scan match is weighed against the motion prior: the camera holds the
// heading far better than wheels do over a few metres, the odometry gives the scale. A camera
// measurement the motion cannot explain (moving objects, a blurred or featureless view) is left
// out by a chi-square test instead of a rule.
#include "urbanslam/slam/CameraClosure.h"
#include "urbanslam/slam/LocalSlam.h"

namespace urbanslam::slam {

struct CameraMotionResult {
  KeyframeConstraint constraint;  // the motion, refined by the camera when it was used
  bool used = false;
  double chi2 = 0;  // of the camera's (bearing, heading) against the motion's prediction
};

// The camera's (bearing, heading) predicted for a vehicle motion `r` (x_i at the origin, x_j = r)
// with the camera at `mount`.
Eigen::Vector2d predictedCameraView(const esdf::Vec3& r, const common::Pose2& mount);

// Maximum a posteriori motion given the odometry increment (motion.z, motion.cov) and the camera
// measurement; the camera is used when its innovation passes the chi-square test at
// `gate_probability` (2 degrees of freedom) and the motion moved the camera at least
// `min_baseline_m` (below that the direction of travel is noise).
CameraMotionResult fuseCameraMotion(const KeyframeConstraint& motion, const CameraMeasurement& camera, double gate_probability,
                                    double min_baseline_m = 0.2);

}  // namespace urbanslam::slam
