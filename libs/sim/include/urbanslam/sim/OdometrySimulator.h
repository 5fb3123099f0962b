#pragma once
// Wheel odometry of a car: distance from the wheel encoders (scale error, slip) and heading
// change from the true motion plus a steering-encoder offset, accumulated into a pose in the
// odometry frame as the log readers deliver it. The random errors are first-order Gauss-Markov
// processes in the distance driven, so their statistics per metre do not depend on the rate.
#include "urbanslam/io/Measurements.h"
#include "urbanslam/sim/Driver.h"
#include "urbanslam/sim/Random.h"
#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

class OdometrySimulator {
 public:
  OdometrySimulator(const OdometryOptions& options, double wheelbase_m, uint64_t seed);
  // A reading at the vehicle's current state (the first call only sets the reference).
  io::OdometryReading read(const VehicleState& state, double timestamp);

 private:
  OdometryOptions options_;
  double wheelbase_m_;
  Rng rng_;
  bool started_ = false;
  VehicleState last_;
  common::Pose2 pose_;
  double slip_until_s_ = -1, slip_factor_ = 0;
  // The drifting errors' current values: distance scale, heading per radian turned, heading per metre.
  double scale_error_ = 0, turn_error_ = 0, drift_rad_per_m_ = 0;
};

class GpsSimulator {
 public:
  GpsSimulator(const GpsOptions& options, uint64_t seed);
  // A fix at the vehicle's current state (noise, and a jump while a multipath event lasts), or
  // false during an outage.
  bool read(const VehicleState& state, double timestamp, io::GpsFix& out);

 private:
  GpsOptions options_;
  Rng rng_;
  double last_s_ = 0, outage_until_s_ = -1, multipath_until_s_ = -1;
  double jump_x_ = 0, jump_y_ = 0;
};

}  // namespace urbanslam::sim
