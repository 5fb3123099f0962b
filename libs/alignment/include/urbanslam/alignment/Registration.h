#pragma once
// What every registration step (ICP, PL-ICP, CRF-match) returns: the transform that maps the
// moving set into the reference set's frame, i.e. the pose of the moving scan seen from the
// reference scan (common::between(pose_ref, pose_moving)), plus the final associations that the
// covariance methods reuse.
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::alignment {

struct Correspondence {
  int moving = 0;       // index into the moving set
  int reference = 0;    // index into the reference set
  double weight = 1.0;  // robust-kernel / CRF marginal weight
};

struct RegistrationResult {
  common::Pose2 transform;
  int iterations = 0;
  bool converged = false;
  std::string failure_reason;           // empty when converged
  std::vector<Correspondence> matches;  // at the final transform
  double rms_residual_m = 0;            // of the matched pairs, in the minimised error
};

}  // namespace urbanslam::alignment
