#include "urbanslam/esdf/BearingHeading.h"

#include <cmath>

namespace urbanslam::esdf {

Vec2 bearingHeading(const Vec3& r) { return {std::atan2(r.y(), r.x()), r.z()}; }

Eigen::Matrix<double, 2, 3> bearingHeadingJacobian(const Vec3& r) {
  const double d2 = r.x() * r.x() + r.y() * r.y();
  Eigen::Matrix<double, 2, 3> j;
  j << -r.y() / d2, r.x() / d2, 0, 0, 0, 1;
  return j;
}

RelativeFactor relativeFactor(const BearingHeading& m, double range_m, double range_sigma_m) {
  RelativeFactor f;
  f.z = Vec3(range_m * std::cos(m.bearing_rad), range_m * std::sin(m.bearing_rad), m.heading_rad);
  // The relative pose at error e is z ⊕ e: position t_z + R(heading) e_xy, heading + e_phi. The
  // bearing, heading and range of it, differentiated at e = 0 (rows: bearing, heading, range).
  const double a = m.bearing_rad - m.heading_rad;  // the bearing in z's own frame, where e_xy lives
  Mat3 g;
  g << -std::sin(a) / range_m, std::cos(a) / range_m, 0,  //
      0, 0, 1,                                            //
      std::cos(a), std::sin(a), 0;
  Mat3 info = Mat3::Zero();
  info.topLeftCorner<2, 2>() = m.information;
  info(2, 2) = 1.0 / (range_sigma_m * range_sigma_m);
  f.omega = g.transpose() * info * g;
  f.omega = 0.5 * (f.omega + f.omega.transpose());
  return f;
}

}  // namespace urbanslam::esdf
