#include "urbanslam/sim/LaserSimulator.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Random.h"

namespace urbanslam::sim {

namespace {
constexpr uint64_t kTagLaser = 40;
constexpr double kDeg = M_PI / 180.0;
}  // namespace

LaserSimulator::LaserSimulator(const LaserOptions& options, const CityModel& city, const Traffic* traffic, uint64_t seed)
    : options_(options), city_(city), traffic_(traffic), seed_(seed) {
  increment_ = options.angular_resolution_deg * kDeg;
  const bool full = options.fov_deg >= 360.0 - 1e-9;
  // A full circle has no duplicate beam at +180; a partial fan includes both ends.
  const auto steps = static_cast<size_t>(std::floor(options.fov_deg / options.angular_resolution_deg + 1e-9));
  beams_ = full ? steps : steps + 1;
  angle_min_ = full ? -M_PI : -options.fov_deg * kDeg / 2;
}

io::LaserScan LaserSimulator::scan(uint64_t index, double t, double timestamp, const common::Pose2& vehicle) const {
  io::LaserScan s;
  s.timestamp = timestamp;
  s.label = options_.label;
  s.angle_min_rad = angle_min_;
  s.angle_increment_rad = increment_;
  s.max_range_m = options_.max_range_m;
  s.sensor_pose = laserMount(options_);
  s.ranges.assign(beams_, static_cast<float>(options_.max_range_m));
  s.valid.assign(beams_, 0);
  const common::Pose2 sensor = common::compose(vehicle, s.sensor_pose);
  const Vec2 o{sensor.x, sensor.y};

  std::vector<double> range(beams_, kNoHit);
  for (size_t i = 0; i < beams_; ++i) {
    const double a = sensor.phi + angle_min_ + static_cast<double>(i) * increment_;
    range[i] = city_.raycast(o, {std::cos(a), std::sin(a)}, options_.max_range_m);
  }
  if (traffic_) {
    // Each moving object is tested only against the beams its bounding circle covers.
    for (const MovingObject& m : traffic_->near(o, options_.max_range_m, t, {vehicle.x, vehicle.y})) {
      const Vec2 d = m.centre - o;
      const double dist = norm(d);
      if (dist <= m.radius || dist - m.radius > options_.max_range_m) continue;
      const double half = std::asin(m.radius / dist);
      const double bearing = common::wrapToPi(std::atan2(d.y, d.x) - sensor.phi);
      const long total = static_cast<long>(beams_);
      const long lo = static_cast<long>(std::floor((bearing - half - angle_min_) / increment_));
      const long hi = static_cast<long>(std::ceil((bearing + half - angle_min_) / increment_));
      const long period = std::lround(2 * M_PI / increment_);
      for (long k = lo; k <= hi; ++k) {
        long i = k;
        if (i < 0 || i >= total) i = ((i % period) + period) % period;  // wrap round a full circle
        if (i < 0 || i >= total) continue;
        const double a = sensor.phi + angle_min_ + static_cast<double>(i) * increment_;
        const Vec2 dir{std::cos(a), std::sin(a)};
        for (const Segment& seg : m.outline)
          range[static_cast<size_t>(i)] = std::min(range[static_cast<size_t>(i)], raySegment(o, dir, seg));
      }
    }
  }
  Rng rng(hash64(seed_, kTagLaser, static_cast<int64_t>(index)));
  for (size_t i = 0; i < beams_; ++i) {
    const double noise = rng.normal();
    const bool drop = rng.chance(options_.dropout_probability);
    if (!(range[i] < options_.max_range_m) || drop) continue;
    const double r = range[i] + noise * (options_.range_sigma_m + options_.range_sigma_per_m * range[i]);
    if (r <= 0 || r >= options_.max_range_m) continue;
    s.ranges[i] = static_cast<float>(r);
    s.valid[i] = 1;
  }
  return s;
}

}  // namespace urbanslam::sim
