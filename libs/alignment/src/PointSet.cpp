#include "urbanslam/alignment/PointSet.h"

#include <cmath>

namespace urbanslam::alignment {

Rigid2 Rigid2::fromPose(const common::Pose2& pose) {
  Rigid2 r;
  const double c = std::cos(pose.phi), s = std::sin(pose.phi);
  r.R << c, -s, s, c;
  r.t << pose.x, pose.y;
  return r;
}

PointSet transformed(const PointSet& points, const common::Pose2& pose) {
  const Rigid2 T = Rigid2::fromPose(pose);
  PointSet out(points);
  for (auto& q : out) {
    q.p = T * q.p;
    q.origin = T * q.origin;
    q.cov = T.R * q.cov * T.R.transpose();
  }
  return out;
}

}  // namespace urbanslam::alignment
