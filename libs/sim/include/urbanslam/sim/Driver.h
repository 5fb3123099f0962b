#pragma once
// Drives the car along the streets the route planner picks: keeps to the right-hand lane's centre
// line by pure pursuit, cruises on straight streets and slows down for turns, within the
// vehicle's acceleration and steering limits. The path is generated a little ahead and dropped
// behind, so a drive of any length runs in constant memory.
#include <deque>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/sim/RoutePlanner.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

struct VehicleState {
  double time_s = 0;   // since the start of the drive
  common::Pose2 pose;  // rear axle, world frame
  double speed_mps = 0;
  double steering_rad = 0;
  double odometer_m = 0;  // true distance driven
};

class Driver {
 public:
  Driver(const StreetGrid& grid, const SimOptions& options);

  // Integrates up to time t (seconds since the start; t >= state().time_s). Controls change on a
  // fixed step_s clock, so the trajectory does not depend on when it is sampled.
  void advanceTo(double t);
  const VehicleState& state() const { return state_; }
  bool finished() const { return state_.odometer_m >= route_length_m_; }
  const RoutePlanner& planner() const { return planner_; }

 private:
  struct PathPoint {
    Vec2 p;
    double s = 0;            // arc length along the path
    double speed_limit = 0;  // at this point (slow through turns)
  };
  void extendPath();
  double clearance(NodeId n) const;
  void control();

  const StreetGrid& grid_;
  VehicleOptions vehicle_;
  RouteOptions route_;
  double route_length_m_;
  RoutePlanner planner_;
  std::deque<NodeId> nodes_;  // the next intersections (the first is the one just left)
  std::deque<PathPoint> path_;
  size_t seg_ = 0;  // the vehicle is on path_[seg_] -> path_[seg_ + 1]
  VehicleState state_;
  double next_control_s_ = 0;
};

}  // namespace urbanslam::sim
