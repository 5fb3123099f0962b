#pragma once
// Kinematic bicycle model of a car, rear-axle reference point: heading rate = v tan(steering) / L.
// Integrated exactly for a step of constant speed and steering (an arc of radius L / tan(steering)),
// so the pose does not drift with the step size.
#include <cmath>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::sim {

inline common::Pose2 stepBicycle(const common::Pose2& p, double speed_mps, double steering_rad, double dt, double wheelbase_m) {
  const double ds = speed_mps * dt;
  const double dphi = ds * std::tan(steering_rad) / wheelbase_m;
  if (std::fabs(dphi) < 1e-9) {
    // Straight (or nearly): the chord along the mean heading is exact to second order.
    const double h = p.phi + dphi / 2;
    return {p.x + ds * std::cos(h), p.y + ds * std::sin(h), common::wrapToPi(p.phi + dphi)};
  }
  const double r = ds / dphi;
  return {p.x + r * (std::sin(p.phi + dphi) - std::sin(p.phi)), p.y - r * (std::cos(p.phi + dphi) - std::cos(p.phi)),
          common::wrapToPi(p.phi + dphi)};
}

}  // namespace urbanslam::sim
