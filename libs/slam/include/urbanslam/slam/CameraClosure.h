#pragma once
// A Tree of Words proposal measured by the camera alone (thesis ch. 6), turned into a
// relative-pose factor between the two keyframes' vehicle poses:
//  * the full planar pose of the second camera seen from the first, when the earlier keyframe's
//    neighbouring image gave its features a depth (vision_loop/MetricRelativePose.h: motion
//    stereo with the odometry's baseline, then perspective-n-point);
//  * else bearing and heading only (vision_loop/PlanarRelativePose.h): a single pair does not see
//    the length of the translation, so the factor is placed at the current estimate's range with
//    a weak range (esdf/BearingHeading.h), and the scale comes from the odometry and from other
//    closures seen from other bearings.
#include <optional>

#include "urbanslam/esdf/BearingHeading.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/vision_loop/MetricRelativePose.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"

namespace urbanslam::slam {

struct CameraMeasurement {
  vision_loop::PlanarRelativePose relative;  // camera j seen from camera i
  vision_loop::MetricRelativePose metric;    // the same with its length, when measured (valid)
  common::Pose2 mount;                       // the camera on the vehicle
};

// The intrinsics of the image the features were extracted from: the calibration is of the image
// as delivered, the features may come from a downscaled copy (`width_px` wide).
vision_loop::PinholeCamera pinholeFor(const io::CameraCalibration& c, int image_width_px, int features_width_px);

// The factor on the vehicle poses x_i, x_j equivalent to the camera's full pose (when valid) or its
// bearing and heading between the cameras x_i ⊕ mount and x_j ⊕ mount: z and Ω for Esdf::observeRelative (error ⊖z ⊕ (⊖x_i ⊕ x_j)).
// The camera-frame factor c = ⊖m ⊕ r ⊕ m is carried to r = m ⊕ c ⊕ ⊖m, whose error is the
// camera-frame error moved by the mount's adjoint (exact to first order in the error).
esdf::RelativeFactor cameraFactor(const CameraMeasurement& m, const esdf::Vec3& x_i, const esdf::Vec3& x_j);

// The nearest the scene both images show can lie, by the estimate: the distance between the two
// cameras (x_i ⊕ mount, x_j ⊕ mount) less three standard deviations of the relative position
// (`relative_cov`, of ⊖x_i ⊕ x_j; its worst direction), at least 0, times the depth per metre of
// baseline that the images give (PlanarRelativePose::depth_per_baseline). 0 when the estimate
// allows the cameras to coincide.
double nearestSceneDepth(const CameraMeasurement& m, const esdf::Vec3& x_i, const esdf::Vec3& x_j, const Eigen::Matrix3d& relative_cov);

}  // namespace urbanslam::slam
