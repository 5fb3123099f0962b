#include "urbanslam/vision_loop/CandidateSelection.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

std::vector<ImageId> selectCandidates(const std::vector<common::Pose2>& image_poses, const std::vector<PositionCovariance>& covariances,
                                      const common::Pose2& current, const CandidateGateOptions& options) {
  if (covariances.size() != image_poses.size()) throw common::InputError("selectCandidates: one covariance per image pose expected");
  std::vector<ImageId> out;
  const double floor = options.min_sigma_m * options.min_sigma_m;
  for (size_t i = 0; i < image_poses.size(); ++i) {
    double dx = image_poses[i].x - current.x, dy = image_poses[i].y - current.y;
    const double d = std::hypot(dx, dy);
    // Positions within view range are as good as coincident: shrink the offset by the range.
    const double shrink = d > options.view_range_m ? (d - options.view_range_m) / d : 0.0;
    dx *= shrink, dy *= shrink;
    const double a = covariances[i].xx + floor, b = covariances[i].xy, c = covariances[i].yy + floor;
    const double det = a * c - b * b;
    if (!(det > 0)) continue;  // not a covariance
    const double m2 = (c * dx * dx - 2 * b * dx * dy + a * dy * dy) / det;
    if (m2 <= options.chi2_gate) out.push_back(static_cast<ImageId>(i));
  }
  return out;
}

}  // namespace urbanslam::vision_loop
