#pragma once
// Which earlier images may show the current place, given the filter's pose estimate and its
// uncertainty (thesis ch. 5: loop closure candidates from the ESDF covariances). The image
// database query is then restricted to these (QueryOptions::candidates), which both saves time
// on long runs and rules out look-alike places that are geometrically impossible.
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/vision_loop/ImageDatabase.h"

namespace urbanslam::vision_loop {

// Covariance of the relative position (x, y) of an earlier image with respect to the current
// pose, world frame, m². The filter computes it (Σ_ii + Σ_cc − Σ_ic − Σ_ci).
struct PositionCovariance {
  double xx = 0, xy = 0, yy = 0;
};

struct CandidateGateOptions {
  double chi2_gate = 9.21;    // χ²(2 DOF) at 99 %
  double view_range_m = 5.0;  // two camera positions this close may see the same place
  double min_sigma_m = 0.1;   // floor on the covariance (a near-singular Σ would gate out everything)
};

// Images i (ids = indices of `image_poses`) whose position, less view_range_m, is within the
// χ² gate of the current position. `covariances` has one entry per image.
std::vector<ImageId> selectCandidates(const std::vector<common::Pose2>& image_poses, const std::vector<PositionCovariance>& covariances,
                                      const common::Pose2& current, const CandidateGateOptions& options = {});

}  // namespace urbanslam::vision_loop
