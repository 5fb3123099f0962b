#pragma once
// Beam geometry of CARMEN-family laser messages (CARMEN FLASER/RLASER/ROBOTLASER1 and GMapping's
// LASER_READING, which GMapping reads from CARMEN logs).
#include <cmath>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::io::detail {

// Angular resolution of a scan with n beams over the usual 180° (SICK LMS modes).
inline double resolutionForBeams(long n) {
  constexpr double kDeg = M_PI / 180.0;
  if (n == 180 || n == 181) return 1.0 * kDeg;
  if (n == 360 || n == 361) return 0.5 * kDeg;
  if (n == 720 || n == 721) return 0.25 * kDeg;
  return n > 1 ? M_PI / static_cast<double>(n - 1) : M_PI;
}

// CARMEN beams start at start_angle and go counter-clockwise. We keep MRPT's symmetric beam
// layout (beam 0 at -aperture/2) and put the asymmetry into the sensor's yaw, so scans convert
// to CObservation2DRangeScan and back without loss.
inline void setBeamGeometry(LaserScan& scan, double start_angle, double resolution, const common::Pose2& mount) {
  const double n = static_cast<double>(scan.ranges.size());
  const double aperture = resolution * (n - 1);
  scan.angle_increment_rad = resolution;
  scan.angle_min_rad = -aperture / 2;
  scan.sensor_pose = {mount.x, mount.y, common::wrapToPi(mount.phi + start_angle + aperture / 2)};
}

}  // namespace urbanslam::io::detail
