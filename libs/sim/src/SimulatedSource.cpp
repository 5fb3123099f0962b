#include "urbanslam/sim/SimulatedSource.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace urbanslam::sim {

SimulatedSource::SimulatedSource(const SimOptions& options)
    : io::DataSource("simulated city (seed " + std::to_string(options.city.seed) + ")"), options_(options) {
  const auto seed = static_cast<uint64_t>(options.city.seed);
  city_ = std::make_unique<CityModel>(options.city);
  traffic_ = std::make_unique<Traffic>(city_->streets(), options.traffic);
  driver_ = std::make_unique<Driver>(city_->streets(), options);
  if (options.laser.enabled) laser_ = std::make_unique<LaserSimulator>(options.laser, *city_, traffic_.get(), seed);
  if (options.camera.enabled) camera_ = std::make_unique<CameraRenderer>(options.camera, *city_, seed);
  if (options.odometry.enabled) odometry_ = std::make_unique<OdometrySimulator>(options.odometry, options.vehicle.wheelbase_m, seed);
  if (options.gps.enabled) gps_ = std::make_unique<GpsSimulator>(options.gps, seed);
}

double SimulatedSource::progress() const { return std::min(1.0, driver_->state().odometer_m / (options_.route.route_length_km * 1000.0)); }

void SimulatedSource::produce() {
  // Sensor clocks are k / rate exactly (no accumulated rounding); equal times fire together.
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double tl = laser_ ? static_cast<double>(laser_count_) / options_.laser.rate_hz : inf;
  const double to = odometry_ ? static_cast<double>(odometry_count_) / options_.odometry.rate_hz : inf;
  const double tg = gps_ ? static_cast<double>(gps_count_) / options_.gps.rate_hz : inf;
  const double tc = camera_ ? static_cast<double>(camera_count_) / options_.camera.rate_hz : inf;
  const double t = std::min({tl, to, tg, tc});
  if (t == inf || driver_->finished()) {
    done_ = true;
    return;
  }
  driver_->advanceTo(t);
  const VehicleState& s = driver_->state();
  const double stamp = options_.route.start_time_s + t;
  constexpr double eps = 1e-9;
  if (to <= t + eps) {
    pending_.push_back(odometry_->read(s, stamp));
    ++odometry_count_;
  }
  if (tg <= t + eps) {
    io::GpsFix fix;
    if (gps_->read(s, stamp, fix)) pending_.push_back(fix);
    ++gps_count_;
  }
  const bool scan = tl <= t + eps, image = tc <= t + eps;
  if (scan || image) pending_.push_back(io::ReferencePose{stamp, s.pose});
  auto see = [&](double r) {
    for (int tx = city_->tileOf(s.pose.x - r); tx <= city_->tileOf(s.pose.x + r); ++tx)
      for (int ty = city_->tileOf(s.pose.y - r); ty <= city_->tileOf(s.pose.y + r); ++ty) seen_tiles_.insert({tx, ty});
  };
  if (scan) {
    pending_.push_back(laser_->scan(laser_count_, t, stamp, s.pose));
    see(options_.laser.max_range_m);
    ++laser_count_;
  }
  if (image) {
    const auto start = std::chrono::steady_clock::now();
    pending_.push_back(camera_->render(camera_count_, stamp, common::compose(s.pose, cameraMount(options_.camera))));
    render_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    see(options_.camera.max_range_m);
    ++camera_count_;
  }
}

bool SimulatedSource::next(io::Measurement& out) {
  while (pending_.empty() && !done_) produce();
  if (pending_.empty()) return false;
  out = std::move(pending_.front());
  pending_.pop_front();
  return true;
}

}  // namespace urbanslam::sim
