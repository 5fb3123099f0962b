#pragma once
// A forward-looking camera's measurement of the full relative pose `ahead_m` straight ahead,
// centimetre-certain, of a scene half the baseline deep (within max_scene_depth_m): the image
// closures that the global SLAM tests propose.
#include <Eigen/Core>

#include "urbanslam/slam/CameraClosure.h"

namespace urbanslam::test {

inline slam::CameraMeasurement cameraAhead(double ahead_m) {
  slam::CameraMeasurement m;
  m.mount = common::Pose2{0.0, 0.0, 0.0};
  m.relative.valid = true;
  m.relative.cov = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  m.relative.depth_per_baseline = 0.5;
  m.metric.valid = true;
  m.metric.pose = common::Pose2{ahead_m, 0.0, 0.0};
  m.metric.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
  return m;
}

}  // namespace urbanslam::test
