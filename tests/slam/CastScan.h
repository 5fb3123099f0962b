#pragma once
// A world of line segments, some of them on things that move, and a front 180° scan at half a
// degree cast into it with 1 cm range noise: the scenes the moving-point tests drive through,
// where the segments say which returns moved.
#include <cmath>
#include <random>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::test {

struct Segment {
  double x1, y1, x2, y2;
  bool moving;
};

// The outline of the box [x0, x1] x [y0, y1].
inline void addBox(std::vector<Segment>& w, double x0, double y0, double x1, double y1, bool moving) {
  for (const Segment& s :
       {Segment{x0, y0, x1, y0, moving}, Segment{x1, y0, x1, y1, moving}, Segment{x1, y1, x0, y1, moving}, Segment{x0, y1, x0, y0, moving}})
    w.push_back(s);
}

// The scan from a sensor `sensor_x_m` ahead of the vehicle; a beam that hits nothing within
// max_range_m has no return. `on_moving` (when given) says per beam whether it ended on a moving
// segment. The noise is drawn for the returns only, in beam order.
inline io::LaserScan castScan(const common::Pose2& vehicle, const std::vector<Segment>& w, double sensor_x_m, double max_range_m,
                              std::mt19937& rng, std::vector<bool>* on_moving = nullptr) {
  io::LaserScan s;
  s.angle_min_rad = -M_PI / 2;
  s.angle_increment_rad = M_PI / 360;
  s.max_range_m = max_range_m;
  s.sensor_pose = {sensor_x_m, 0, 0};
  const common::Pose2 sensor = common::compose(vehicle, s.sensor_pose);
  std::normal_distribution<double> noise(0, 0.01);
  if (on_moving) on_moving->clear();
  for (int i = 0; i <= 360; ++i) {
    const double a = sensor.phi + s.bearing(static_cast<size_t>(i));
    const double dx = std::cos(a), dy = std::sin(a);
    double best = HUGE_VAL;
    bool moving = false;
    for (const Segment& g : w) {
      // sensor + t d = g1 + u (g2 - g1)
      const double ex = g.x2 - g.x1, ey = g.y2 - g.y1;
      const double den = dx * ey - dy * ex;
      if (std::abs(den) < 1e-12) continue;
      const double t = ((g.x1 - sensor.x) * ey - (g.y1 - sensor.y) * ex) / den;
      const double u = ((g.x1 - sensor.x) * dy - (g.y1 - sensor.y) * dx) / den;
      if (t > 0 && u >= 0 && u <= 1 && t < best) best = t, moving = g.moving;
    }
    const bool hit = best < max_range_m;
    s.ranges.push_back(hit ? static_cast<float>(best + noise(rng)) : static_cast<float>(max_range_m));
    s.valid.push_back(hit ? 1 : 0);
    if (on_moving) on_moving->push_back(hit && moving);
  }
  return s;
}

}  // namespace urbanslam::test
