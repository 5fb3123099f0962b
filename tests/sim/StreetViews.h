#pragma once
// Camera poses along the simulated drive of the 1 km² test city, for the camera tests.
#include <cmath>

#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/Driver.h"

namespace urbanslam::sim::test {

inline CityOptions city1km() {
  CityOptions o;
  o.seed = 1;
  o.area_km2 = 1.0;
  return o;
}

// Camera pose on the drive of a 1 km2 city after t seconds, looking left (as ini/city-camera.ini).
inline common::Pose2 streetView(const StreetGrid& grid, double t, double forward_m = 0) {
  SimOptions o;
  o.city = grid.options();
  Driver driver(grid, o);
  driver.advanceTo(t);
  common::Pose2 p = driver.state().pose;
  p.x += forward_m * std::cos(p.phi);
  p.y += forward_m * std::sin(p.phi);
  return common::compose(p, {1.0, 0.0, M_PI / 2});
}

}  // namespace urbanslam::sim::test
