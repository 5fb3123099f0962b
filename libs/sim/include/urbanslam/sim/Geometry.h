#pragma once
// Planar primitives of the simulated world: wall segments, boxes, and the ray-segment
// intersection every sensor is built on.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace urbanslam::sim {

struct Vec2 {
  double x = 0, y = 0;
};
inline Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
inline Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
inline double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
inline double norm(Vec2 a) { return std::hypot(a.x, a.y); }

// What a wall is made of, for the camera (the laser sees only geometry).
enum class SurfaceKind : uint8_t { Facade, Featureless, Pillar, Tree, LampPost, ParkedCar, Barrier, Fountain, Bench, Island };

// The appearance of a surface: `id` selects its procedural texture (facades of one repeated
// design share it), height_m is how tall it stands (the map is 2D).
struct SurfaceLook {
  uint32_t id = 0;
  SurfaceKind kind = SurfaceKind::Facade;
  float height_m = 0;
};

// A wall: the laser sees both sides (footprints are closed outlines, so which side faces the
// street needs no bookkeeping). u0_m is the texture coordinate at `a`: the texture runs along
// the segment from there, so a facade made of several segments keeps one continuous texture.
struct Segment {
  Vec2 a, b;
  SurfaceLook look{};
  float u0_m = 0;
};

struct Box {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool overlaps(const Box& o) const { return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
  bool contains(Vec2 p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
};

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Distance t >= 0 along the ray origin + t * dir (dir of unit length) to the segment, or kNoHit.
inline double raySegment(Vec2 origin, Vec2 dir, const Segment& s) {
  const Vec2 e = s.b - s.a;
  const double den = cross(dir, e);
  if (std::fabs(den) < 1e-12) return kNoHit;  // parallel: a grazing ray sees no surface
  const Vec2 w = s.a - origin;
  const double t = cross(w, e) / den;
  const double u = cross(w, dir) / den;
  if (t < 0 || u < 0 || u > 1) return kNoHit;
  return t;
}

// Clips a segment to a box (Liang-Barsky); false when nothing is left.
inline bool clipSegment(const Segment& s, const Box& b, Segment& out) {
  double t0 = 0, t1 = 1;
  const double dx = s.b.x - s.a.x, dy = s.b.y - s.a.y;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {s.a.x - b.x0, b.x1 - s.a.x, s.a.y - b.y0, b.y1 - s.a.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
    } else {
      const double r = q[i] / p[i];
      if (p[i] < 0)
        t0 = std::max(t0, r);
      else
        t1 = std::min(t1, r);
    }
  }
  if (t0 > t1) return false;
  out = s;
  out.a = {s.a.x + t0 * dx, s.a.y + t0 * dy};
  out.b = {s.a.x + t1 * dx, s.a.y + t1 * dy};
  out.u0_m = static_cast<float>(s.u0_m + t0 * std::hypot(dx, dy));  // the texture stays put
  return true;
}

// Appends the closed outline of a polygon (vertices in order) as segments, the texture running
// round it.
inline void addPolygon(std::vector<Segment>& out, const std::vector<Vec2>& v, const SurfaceLook& look = {}) {
  double u = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const Segment s{v[i], v[(i + 1) % v.size()], look, static_cast<float>(u)};
    u += norm(s.b - s.a);
    out.push_back(s);
  }
}

// An oriented rectangle (a car), centre c, heading h, length l, width w.
inline void addRectangle(std::vector<Segment>& out, Vec2 c, double h, double l, double w, const SurfaceLook& look = {}) {
  const Vec2 f{std::cos(h) * l / 2, std::sin(h) * l / 2}, s{-std::sin(h) * w / 2, std::cos(h) * w / 2};
  addPolygon(out, {c + f + s, c - f + s, c - f - s, c + f - s}, look);
}

// A round object (tree trunk, pedestrian) as a regular polygon: cheap and close enough at laser
// resolution.
inline void addCircle(std::vector<Segment>& out, Vec2 c, double r, int sides = 6, const SurfaceLook& look = {}) {
  std::vector<Vec2> v;
  for (int i = 0; i < sides; ++i) {
    const double a = 2 * M_PI * i / sides;
    v.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  addPolygon(out, v, look);
}

}  // namespace urbanslam::sim
