#pragma once
// Accumulates the vehicle motion since the last keyframe and its covariance, by composing the
// motion model's predictions step by step (F_x Σ F_x' + F_u Q_v F_u' + Q_s each step). Adding the
// result as one relative constraint to the ESDF is the same, to first order, as predicting with
// augmentation at every reading and marginalising the intermediate poses — without ever
// storing them, so the filter holds one pose per keyframe.
#include <Eigen/Core>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

class MotionIntegrator {
 public:
  MotionIntegrator(const MotionOptions& motion, const VehicleOptions& vehicle);

  // Starts a new interval at the current vehicle pose (keeps the last readings).
  void reset();
  void addOdometry(const io::OdometryReading& m);
  void addDrive(const io::DriveReading& m);

  // Motion since reset() in the frame of the pose at reset(), and its covariance.
  const common::Pose2& increment() const { return increment_; }
  const Eigen::Matrix3d& covariance() const { return cov_; }
  // Accumulated odometry pose (for the odometry-rate trajectory), and whether any input came.
  const common::Pose2& odometryPose() const { return odom_; }
  bool hasInput() const { return have_input_; }

  // The interval so far and the last readings (the options are the constructor's).
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r);

 private:
  void accumulate(const Eigen::Vector3d& step, const Eigen::Matrix3d& step_cov);

  MotionOptions motion_;
  VehicleOptions vehicle_;
  common::Pose2 increment_, odom_;
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d odometry_sqrt_ = Eigen::Matrix3d::Zero();  // cov_ = this * this' for wheel odometry
  bool have_input_ = false, have_odom_ = false, have_drive_ = false;
  io::OdometryReading last_odom_;
  io::DriveReading last_drive_;
};

}  // namespace urbanslam::slam
