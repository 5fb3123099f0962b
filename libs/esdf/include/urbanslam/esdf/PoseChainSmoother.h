#pragma once
// Smoothing of a chain of 2D poses: each pose follows the previous one by a relative motion with
// its covariance, and some poses are measured in the world frame (fixes). The forward pass is an
// extended Kalman filter, one pose at a time in constant time (filtered()); smooth() adds the
// Rauch-Tung-Striebel backward pass, which gives every pose its estimate given all the fixes,
// those after it too, and repeats both passes linearised about the last smoothed chain until it
// stops moving: Gauss-Newton on the chain's least-squares problem, so the result is the batch
// optimum, at a cost linear in the chain's length. A filter alone lags behind its fixes and
// jumps where a fix corrects it; the smoothed chain bends gradually instead, as the relative
// motions' covariances allow.
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::esdf {

class PoseChainSmoother {
 public:
  // The next pose: `motion` from the previous one in its frame, with covariance `cov` (both
  // ignored for the first pose). Returns its index.
  size_t addPose(const common::Pose2& motion, const Eigen::Matrix3d& cov);
  // A measurement of the newest pose in the world frame, with its covariance. Poses before the
  // first fix have no estimate of their own: smooth() places them back from it along the chain.
  void addFix(const common::Pose2& pose, const Eigen::Matrix3d& cov);

  size_t size() const { return nodes_.size(); }
  bool hasFix() const { return first_fixed_ < nodes_.size(); }
  // The filter's estimate of the newest pose (given the fixes so far); hasFix() required.
  common::Pose2 filtered() const;
  // Every pose given every fix, headings wrapped; empty without any fix. `max_iterations`
  // forward-backward passes at most (1: the plain RTS smoother, linearised where the filter was);
  // they stop once no pose moves by `tolerance` (metres, radians).
  std::vector<common::Pose2> smooth(int max_iterations = 10, double tolerance = 1e-9) const;

 private:
  struct Fix {
    Eigen::Vector3d pose;
    Eigen::Matrix3d cov;
  };
  struct Node {
    Eigen::Vector3d motion;  // from the previous pose
    Eigen::Matrix3d motion_cov;
    std::vector<Fix> fixes;
  };
  // One forward-backward pass, linearised about `about` (the last smoothed chain; empty: where
  // the filter is). Returns the smoothed chain from the first fixed pose on.
  std::vector<Eigen::Vector3d> pass(const std::vector<Eigen::Vector3d>& about) const;

  std::vector<Node> nodes_;
  size_t first_fixed_ = static_cast<size_t>(-1);
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();  // the filter's estimate of the newest pose, and its covariance
  Eigen::Matrix3d p_ = Eigen::Matrix3d::Identity();
};

}  // namespace urbanslam::esdf
