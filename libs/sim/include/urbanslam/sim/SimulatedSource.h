#pragma once
// The simulation as a data source: laser scans, camera images, wheel odometry, GPS fixes and the
// ground-truth pose at every scan and image (ReferencePose, just before them), in time order,
// generated as they are asked for (a drive of any length never sits in memory).
#include <deque>
#include <memory>
#include <set>
#include <utility>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/sim/CameraRenderer.h"
#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/Driver.h"
#include "urbanslam/sim/LaserSimulator.h"
#include "urbanslam/sim/OdometrySimulator.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/Traffic.h"

namespace urbanslam::sim {

class SimulatedSource : public io::DataSource {
 public:
  explicit SimulatedSource(const SimOptions& options);

  bool next(io::Measurement& out) override;
  double progress() const override;
  std::string format() const override { return "urbanslam city simulation"; }

  const CityModel& city() const { return *city_; }
  const VehicleState& vehicle() const { return driver_->state(); }
  const Driver& driver() const { return *driver_; }
  // Tiles within laser range of the vehicle at some scan: the part of the city the drive saw.
  const std::set<std::pair<int, int>>& seenTiles() const { return seen_tiles_; }
  size_t scans() const { return laser_count_; }
  size_t images() const { return camera_count_; }
  // The camera (null when disabled) and the wall time spent rendering so far.
  const CameraRenderer* camera() const { return camera_.get(); }
  double renderSeconds() const { return render_s_; }

 private:
  void produce();

  SimOptions options_;
  std::unique_ptr<CityModel> city_;
  std::unique_ptr<Traffic> traffic_;
  std::unique_ptr<Driver> driver_;
  std::unique_ptr<LaserSimulator> laser_;
  std::unique_ptr<CameraRenderer> camera_;
  std::unique_ptr<OdometrySimulator> odometry_;
  std::unique_ptr<GpsSimulator> gps_;
  uint64_t laser_count_ = 0, camera_count_ = 0, odometry_count_ = 0, gps_count_ = 0;
  double render_s_ = 0;
  std::deque<io::Measurement> pending_;
  std::set<std::pair<int, int>> seen_tiles_;
  bool done_ = false;
};

}  // namespace urbanslam::sim
