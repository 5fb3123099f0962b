#pragma once
// The one closed-form 2D rigid fit of the project (Arun / Umeyama without scale): the rotation
// and translation that map src[i] onto dst[i] best in the weighted least-squares sense. ICP and
// CRF-match solve for a scan's pose with it; trajectory evaluation aligns an estimate onto a
// reference with it.
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::common {

// weights empty: all 1. Returns false when there are fewer than two pairs, the sizes differ,
// the total weight is not positive or the result is not finite.
bool fitRigid2D(const std::vector<Eigen::Vector2d>& src, const std::vector<Eigen::Vector2d>& dst, const std::vector<double>& weights,
                Pose2* transform);

}  // namespace urbanslam::common
