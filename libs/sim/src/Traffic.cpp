#include "urbanslam/sim/Traffic.h"

#include <cmath>

#include "urbanslam/sim/Random.h"

namespace urbanslam::sim {

namespace {
constexpr uint64_t kTagStream = 30, kTagMember = 31;
}

Traffic::Traffic(const StreetGrid& grid, const TrafficOptions& options) : grid_(grid), options_(options) {}

std::vector<MovingObject> Traffic::near(Vec2 centre, double radius, double t, Vec2 ego) const {
  std::vector<MovingObject> out;
  const int n = grid_.lineCount();
  const double half = grid_.streetWidth() / 2;
  struct Stream {
    double offset, spacing, speed;
    bool car;
  };
  std::vector<Stream> streams;
  if (options_.car_spacing_m > 0)
    for (double dir : {1.0, -1.0})
      streams.push_back({dir * grid_.laneOffset(), options_.car_spacing_m, dir * options_.car_speed_mps, true});
  if (options_.pedestrian_spacing_m > 0)
    for (double side : {1.0, -1.0})
      for (double dir : {1.0, -1.0})
        streams.push_back({side * (half - grid_.sidewalkWidth() * 0.3), options_.pedestrian_spacing_m,
                           dir * options_.pedestrian_speed_mps * (side > 0 ? 1.0 : 0.8), false});

  for (int axis = 0; axis < 2; ++axis) {
    // Streets along axis 0 are the horizontal lines (constant y), along axis 1 the vertical ones.
    const double across = axis == 0 ? centre.y : centre.x, along_c = axis == 0 ? centre.x : centre.y;
    const int line_axis = axis == 0 ? 1 : 0;
    const int l0 = std::max(0, grid_.lineBelow(line_axis, across - radius - half));
    const int l1 = std::min(n - 1, grid_.lineBelow(line_axis, across + radius + half) + 1);
    const double lo = grid_.linePos(axis, 0), hi = grid_.linePos(axis, n - 1);
    for (int l = l0; l <= l1; ++l) {
      const double c = grid_.linePos(line_axis, l);
      for (size_t si = 0; si < streams.size(); ++si) {
        const Stream& st = streams[si];
        // Right-hand traffic: moving towards +along, the lane is on the right (-y for axis 0, +x for axis 1).
        const double lateral = axis == 0 ? -st.offset : st.offset;
        const double phase = unitFromHash(hash64(grid_.seed(), kTagStream, axis, l, static_cast<int64_t>(si))) * st.spacing;
        const double shift = phase + st.speed * t;
        const long k0 = static_cast<long>(std::floor((along_c - radius - shift) / st.spacing)) - 1;
        const long k1 = static_cast<long>(std::ceil((along_c + radius - shift) / st.spacing)) + 1;
        for (long k = k0; k <= k1; ++k) {
          const uint64_t h = hash64(grid_.seed(), kTagMember, axis * 1000003 + l, static_cast<int64_t>(si), k);
          const double along = shift + k * st.spacing + (unitFromHash(h) - 0.5) * 0.5 * st.spacing;
          if (along < lo || along > hi) continue;  // streets end at the city's edge
          // Not inside a dead end's closed half (or the open one: nobody drives into them).
          const int node = grid_.lineBelow(axis, along);
          if (axis == 0 ? grid_.edge(0, node, l) != EdgeState::Open : grid_.edge(1, l, node) != EdgeState::Open) continue;
          const Vec2 p = axis == 0 ? Vec2{along, c + lateral} : Vec2{c + lateral, along};
          if (norm(p - centre) > radius + 3 || norm(p - ego) < options_.clearance_m) continue;
          // The streams follow the grid's lines: none through a roundabout's island and ring.
          if (grid_.nearRoundabout(p, grid_.ringOuterRadius() + 3.0)) continue;
          MovingObject m;
          m.centre = p;
          const double heading = (axis == 0 ? 0.0 : M_PI / 2) + (st.speed < 0 ? M_PI : 0.0);
          if (st.car) {
            m.radius = 2.6;
            addRectangle(m.outline, p, heading, 4.5, 1.8);
          } else {
            m.radius = 0.35;
            addCircle(m.outline, p, 0.3, 5);
          }
          out.push_back(std::move(m));
        }
      }
    }
  }
  return out;
}

}  // namespace urbanslam::sim
