#include "urbanslam/sim/OdometrySimulator.h"

#include <cmath>

namespace urbanslam::sim {

namespace {
constexpr uint64_t kTagOdometry = 50, kTagGps = 51;
}

OdometrySimulator::OdometrySimulator(const OdometryOptions& options, double wheelbase_m, uint64_t seed)
    : options_(options), wheelbase_m_(wheelbase_m), rng_(hash64(seed, kTagOdometry)) {}

io::OdometryReading OdometrySimulator::read(const VehicleState& s, double timestamp) {
  if (!started_) {
    started_ = true;
    last_ = s;
    return {timestamp, pose_};
  }
  const double dt = s.time_s - last_.time_s;
  const double ds_true = s.odometer_m - last_.odometer_m;
  const double dphi_true = common::wrapToPi(s.pose.phi - last_.pose.phi);
  if (rng_.chance(options_.slip_probability * dt)) {
    slip_until_s_ = s.time_s + options_.slip_duration_s;
    slip_factor_ = rng_.uniform(0, options_.slip_scale);
  }
  const double slip = s.time_s < slip_until_s_ ? slip_factor_ : 0.0;
  // Gauss-Markov step over the distance driven: stationary standard deviation sigma, correlation
  // exp(-distance / correlation_length_m).
  const double a = std::exp(-std::fabs(ds_true) / options_.correlation_length_m), q = std::sqrt(1 - a * a);
  scale_error_ = a * scale_error_ + q * rng_.normal(options_.sigma_per_m);
  turn_error_ = a * turn_error_ + q * rng_.normal(options_.sigma_per_rad);
  drift_rad_per_m_ = a * drift_rad_per_m_ + q * rng_.normal(options_.sigma_phi_per_m_rad);
  const double ds = ds_true * (1 + options_.scale_bias + slip + scale_error_);
  // The heading the car computes from its steering encoder: an offset bends every straight.
  const double bias = options_.steering_bias_deg * M_PI / 180.0;
  const double steer_error = ds_true * (std::tan(s.steering_rad + bias) - std::tan(s.steering_rad)) / wheelbase_m_;
  const double dphi = dphi_true * (1 + turn_error_) + steer_error + drift_rad_per_m_ * std::fabs(ds_true);
  pose_ = common::compose(pose_, {ds * std::cos(dphi / 2), ds * std::sin(dphi / 2), dphi});
  last_ = s;
  return {timestamp, pose_};
}

GpsSimulator::GpsSimulator(const GpsOptions& options, uint64_t seed) : options_(options), rng_(hash64(seed, kTagGps)) {}

bool GpsSimulator::read(const VehicleState& s, double timestamp, io::GpsFix& out) {
  const double dt = s.time_s - last_s_;
  last_s_ = s.time_s;
  if (s.time_s >= outage_until_s_ && rng_.chance(options_.outage_probability * dt))
    outage_until_s_ = s.time_s + rng_.uniform(options_.outage_min_s, options_.outage_max_s);
  if (s.time_s >= multipath_until_s_ && rng_.chance(options_.multipath_probability * dt)) {
    multipath_until_s_ = s.time_s + options_.multipath_duration_s;
    const double dir = rng_.uniform(-M_PI, M_PI);
    jump_x_ = options_.multipath_jump_m * std::cos(dir);
    jump_y_ = options_.multipath_jump_m * std::sin(dir);
  }
  const double nx = rng_.normal(options_.sigma_m), ny = rng_.normal(options_.sigma_m);
  if (s.time_s < outage_until_s_) return false;
  const bool jumped = s.time_s < multipath_until_s_;
  out = {timestamp, s.pose.x + nx + (jumped ? jump_x_ : 0), s.pose.y + ny + (jumped ? jump_y_ : 0)};
  return true;
}

}  // namespace urbanslam::sim
