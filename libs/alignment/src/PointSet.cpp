#include "urbanslam/alignment/PointSet.h"

#include <cmath>
#include <cstddef>

namespace urbanslam::alignment {

Rigid2 Rigid2::fromPose(const common::Pose2& pose) {
  Rigid2 r;
  const double c = std::cos(pose.phi), s = std::sin(pose.phi);
  r.R << c, -s, s, c;
  r.t << pose.x, pose.y;
  return r;
}

PointSet transformed(const PointSet& points, const common::Pose2& pose) {
  PointSet out;
  appendTransformed(points, pose, &out);
  return out;
}

void appendTransformed(const PointSet& points, const common::Pose2& pose, PointSet* out) {
  const Rigid2 T = Rigid2::fromPose(pose);
  const auto first = static_cast<std::ptrdiff_t>(out->size());
  out->insert(out->end(), points.begin(), points.end());
  for (auto q = out->begin() + first; q != out->end(); ++q) {
    q->p = T * q->p;
    q->origin = T * q->origin;
    q->cov = T.R * q->cov * T.R.transpose();
  }
}

}  // namespace urbanslam::alignment
