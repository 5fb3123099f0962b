#pragma once
// Synthetic laser scans for the alignment tests: ray casting from a known pose against a world
// of line segments (walls, boxes, polygonal "trees"), with Gaussian range noise.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::alignment::test {

struct Segment {
  Eigen::Vector2d a, b;
};
using World = std::vector<Segment>;

inline void addBox(World& w, double x0, double y0, double x1, double y1) {
  w.push_back({{x0, y0}, {x1, y0}});
  w.push_back({{x1, y0}, {x1, y1}});
  w.push_back({{x1, y1}, {x0, y1}});
  w.push_back({{x0, y1}, {x0, y0}});
}

inline void addPolygon(World& w, double cx, double cy, double r, int sides) {
  for (int k = 0; k < sides; ++k) {
    const double a0 = 2 * M_PI * k / sides, a1 = 2 * M_PI * (k + 1) / sides;
    w.push_back({{cx + r * std::cos(a0), cy + r * std::sin(a0)}, {cx + r * std::cos(a1), cy + r * std::sin(a1)}});
  }
}

// A room 20 x 12 m with an L-shaped bay, boxes and a few round pillars: walls, corners, clutter.
inline World roomWorld() {
  World w;
  const std::vector<Eigen::Vector2d> outline = {{-10, -6}, {10, -6}, {10, 2}, {6, 2}, {6, 6}, {-10, 6}};
  for (size_t i = 0; i < outline.size(); ++i) w.push_back({outline[i], outline[(i + 1) % outline.size()]});
  addBox(w, 2, -3, 3.5, -1.5);
  addBox(w, -6, 2, -4, 3);
  addBox(w, 7.5, -4, 8.2, -2.5);
  addPolygon(w, -2, -3, 0.3, 10);
  addPolygon(w, 4, 3.5, 0.25, 10);
  addPolygon(w, -7, -1, 0.4, 10);
  return w;
}

// A long straight corridor along x, 2.4 m wide: nothing constrains motion along it.
inline World corridorWorld() {
  World w;
  w.push_back({{-200, -1.2}, {200, -1.2}});
  w.push_back({{-200, 1.2}, {200, 1.2}});
  return w;
}

// A street along x from x0 to x1 between facades at y = south and y = north, a pillar 1 m wide
// and 0.8 m deep every 4 m along both: a facade of one repeated design, whose pillars' sides each
// view sees from one end of the street only.
inline World pillaredStreetWorld(double south, double north, double x0, double x1) {
  World w;
  w.push_back({{x0, south}, {x1, south}});
  w.push_back({{x0, north}, {x1, north}});
  for (double x = x0; x <= x1; x += 4) {
    addBox(w, x, south, x + 1, south + 0.8);
    addBox(w, x, north - 0.8, x + 1, north);
  }
  return w;
}

struct ScanSpec {
  int beams = 361;
  double fov_rad = M_PI;
  double max_range_m = 30.0;
  double noise_m = 0.01;
  unsigned seed = 7;
};

inline io::LaserScan simulateScan(const World& world, const common::Pose2& pose, const ScanSpec& spec = {}) {
  io::LaserScan s;
  s.label = "SIM";
  s.angle_min_rad = -spec.fov_rad / 2;
  s.angle_increment_rad = spec.fov_rad / (spec.beams - 1);
  s.max_range_m = spec.max_range_m;
  std::mt19937 rng(spec.seed);
  std::normal_distribution<double> nd(0, spec.noise_m);
  for (int i = 0; i < spec.beams; ++i) {
    const double a = pose.phi + s.bearing(i);
    const Eigen::Vector2d o(pose.x, pose.y), d(std::cos(a), std::sin(a));
    double best = std::numeric_limits<double>::infinity();
    for (const auto& seg : world) {
      const Eigen::Vector2d e = seg.b - seg.a;
      const double den = d.x() * (-e.y()) - d.y() * (-e.x());
      if (std::abs(den) < 1e-12) continue;
      const Eigen::Vector2d rhs = seg.a - o;
      const double t = (rhs.x() * (-e.y()) - rhs.y() * (-e.x())) / den;
      const double u = (d.x() * rhs.y() - d.y() * rhs.x()) / den;
      if (t > 0 && u >= 0 && u <= 1) best = std::min(best, t);
    }
    if (best < spec.max_range_m) {
      s.ranges.push_back(static_cast<float>(best + nd(rng)));
      s.valid.push_back(1);
    } else {
      s.ranges.push_back(static_cast<float>(spec.max_range_m));
      s.valid.push_back(0);
    }
  }
  return s;
}

}  // namespace urbanslam::alignment::test
