#pragma once
// A relative pose seen by a camera between two delayed poses, in the plane: the direction of
// the translation (the bearing; an essential matrix fixes the direction of the translation, not
// its length) and the heading change, with their 2x2 information. The filter takes it as a
// relative-pose factor placed at a range along that bearing: the camera informs bearing and
// heading; the scale it cannot see comes from the odometry edges between the two poses, which
// the filter already holds.
#include <Eigen/Core>
#include <algorithm>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

struct BearingHeading {
  double bearing_rad = 0;               // direction of pose j's position seen from pose i (in i's frame)
  double heading_rad = 0;               // heading of j minus heading of i
  Mat2 information = Mat2::Identity();  // of (bearing, heading)
};

// h(r) = (atan2(r.y, r.x), r.phi) of a relative pose r = ⊖x_i ⊕ x_j, and dh/dr.
Vec2 bearingHeading(const Vec3& relative);
Eigen::Matrix<double, 2, 3> bearingHeadingJacobian(const Vec3& relative);

// The relative-pose factor (measurement z and information Ω for Esdf::observeRelative, in the
// g2o error e = ⊖z ⊕ (⊖x_i ⊕ x_j)) equivalent to `m` at the range range_m ± range_sigma_m: to
// second order in e, e'Ωe = [Δbearing Δheading] I [Δbearing Δheading]' + (Δrange / σ)².
// range_m: where to put it (the current estimate's range, from the odometry); range_sigma_m: what
// the factor adds on the range. The odometry edges already carry the scale, so a camera factor
// takes a σ far above the range (weakRangeSigma): it then adds next to nothing on the range and
// only keeps Ω invertible for the innovation gate.
inline double weakRangeSigma(double range_m) { return 1e3 * std::max(range_m, 1.0); }
struct RelativeFactor {
  Vec3 z;
  Mat3 omega;
};
RelativeFactor relativeFactor(const BearingHeading& m, double range_m, double range_sigma_m);

}  // namespace urbanslam::esdf
