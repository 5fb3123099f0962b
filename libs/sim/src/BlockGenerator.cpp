#include "urbanslam/sim/BlockGenerator.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Random.h"
#include "urbanslam/sim/SurfaceTexture.h"

namespace urbanslam::sim {

namespace {

constexpr uint64_t kTagSide = 10, kTagDesign = 11, kTagPark = 12, kTagFurniture = 13;
// Looks are drawn from hashes of their own, never from the geometry's generators: the camera's
// attributes leave the walls the laser sees exactly as they were.
constexpr uint64_t kTagLook = 14, kTagDesignLook = 15, kTagFurnitureLook = 16, kTagParkLook = 17, kTagDeadEndLook = 18;

uint32_t lookId(uint64_t h) { return static_cast<uint32_t>(h >> 32) | 1u; }  // 0 stays "no look"

SurfaceLook makeLook(uint64_t h, SurfaceKind kind) {
  const uint32_t id = lookId(h);
  return {id, kind, static_cast<float>(facadeHeight(id, kind))};
}

// A vertex of a block outline with the look and texture coordinate of the segment it starts.
struct OutlineVertex {
  Vec2 p;
  SurfaceLook look;
  double u = 0;
};

void addOutline(std::vector<Segment>& out, const std::vector<OutlineVertex>& v) {
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back({v[i].p, v[(i + 1) % v.size()].p, v[i].look, static_cast<float>(v[i].u)});
}

// A facade along a block side in side coordinates: u along the side, v into the block (v < 0 is
// the sidewalk). The outline runs from (0, setback) to (width, setback).
struct Facade {
  std::vector<Vec2> outline;
  std::vector<std::vector<Vec2>> extras;  // free-standing pillars
};

Facade plainFacade(double width, double setback) { return {{{0, setback}, {width, setback}}, {}}; }

// A facade with detail a laser sees: doorway recesses, shop-front steps, an arcade of pillars in
// front of a set-back wall. The detail is what makes one street distinguishable from another.
Facade detailedFacade(Rng& rng, double width, double setback) {
  Facade f;
  const bool arcade = width > 9 && rng.chance(0.2);
  const double wall = arcade ? setback + 2.5 : setback;
  f.outline.push_back({0, setback});
  if (arcade) f.outline.push_back({0, wall});
  // Features at non-overlapping slots along the facade.
  double u = rng.uniform(1.0, 3.0);
  while (u < width - 3.0) {
    const double w = rng.uniform(1.2, 2.8);
    if (u + w > width - 1.0) break;
    const double kind = rng.uniform();
    if (kind < 0.45) {  // doorway / recess
      const double d = rng.uniform(0.3, 1.2);
      f.outline.insert(f.outline.end(), {{u, wall}, {u, wall + d}, {u + w, wall + d}, {u + w, wall}});
    } else if (kind < 0.7) {  // shop-front step or bay protruding towards the street
      const double d = rng.uniform(0.25, 0.6);
      f.outline.insert(f.outline.end(), {{u, wall}, {u, wall - d}, {u + w, wall - d}, {u + w, wall}});
    }  // else: a plain stretch
    u += w + rng.uniform(1.0, 5.0);
  }
  if (arcade) {
    f.outline.push_back({width, wall});
    for (double p = 1.0; p < width - 0.5; p += 3.0)
      f.extras.push_back({{p, setback}, {p + 0.5, setback}, {p + 0.5, setback + 0.5}, {p, setback + 0.5}});
  }
  f.outline.push_back({width, setback});
  return f;
}

// One of the few designs that repeat across the city (perceptual aliasing): fixed width and
// detail drawn from the design's own hash.
Facade designFacade(const StreetGrid& g, int design, double& width) {
  const auto& o = g.options();
  Rng rng(hash64(g.seed(), kTagDesign, design));
  width = rng.uniform(o.facade_min_m, o.facade_max_m);
  return detailedFacade(rng, width, 0.0);
}

struct SideFrame {
  Vec2 origin, u, v;  // corner, direction along the side, direction into the block
  Vec2 at(Vec2 p) const { return origin + p.x * u + p.y * v; }
};

// The facades along one side, appended to the block outline (from its start corner, excluding
// its end corner). Corner buildings are flush with the street so the sides join cleanly.
// Each facade carries its look: a repeated design's copies share one (the camera sees the same
// building again), every other facade has its own. Texture coordinates run along the facade's
// outline from its start, so copies of a design are textured identically wherever they stand.
void buildSide(const StreetGrid& g, const SideFrame& s, double length, Rng& rng, int i, int j, int k,
               std::vector<OutlineVertex>& outline, std::vector<Segment>& out) {
  const auto& o = g.options();
  const size_t side_start = outline.size();
  outline.push_back({s.origin, {}, 0.0});
  double u = 0;
  for (int n = 0; u < length - 1e-6; ++n) {
    double w = rng.uniform(o.facade_min_m, o.facade_max_m);
    Facade f;
    SurfaceLook look = makeLook(hash64(g.seed(), kTagLook, i, j, k * 65536 + n), SurfaceKind::Facade);
    const double kind = rng.uniform();
    if (kind < o.featureless_wall_probability) {
      w *= 2;  // long blank walls: a corridor for scan matching
      f = plainFacade(std::min(w, length - u), 0.0);
      w = std::min(w, length - u);
      look = makeLook(hash64(g.seed(), kTagLook, i, j, k * 65536 + n), SurfaceKind::Featureless);
    } else if (kind < o.featureless_wall_probability + o.repeated_design_probability) {
      double dw = 0;
      const int design = static_cast<int>(rng.next() % static_cast<uint64_t>(o.design_count));
      f = designFacade(g, design, dw);
      if (u + dw > length) {
        w = length - u;
        f = plainFacade(w, 0.0);
        look.kind = SurfaceKind::Featureless;
      } else {
        w = dw;
        look = makeLook(hash64(g.seed(), kTagDesignLook, design), SurfaceKind::Facade);
      }
    } else {
      if (length - u - w < o.facade_min_m) w = length - u;  // no sliver at the corner
      const bool corner = u == 0 || u + w >= length - 1e-6;
      const double setback = corner ? 0.0 : (rng.chance(0.5) ? rng.uniform(0.3, 2.0) : 0.0);
      f = detailedFacade(rng, w, setback);
    }
    double fu = 0;  // arc length along this facade's outline
    for (size_t q = 0; q < f.outline.size(); ++q) {
      if (q > 0) fu += norm(f.outline[q] - f.outline[q - 1]);
      outline.push_back({s.at({u + f.outline[q].x, f.outline[q].y}), look, fu});
    }
    if (n == 0) {  // the side's corner vertex starts the first facade's texture
      outline[side_start].look = look;
      outline[side_start].u = -norm(outline[side_start + 1].p - s.origin);
    }
    for (const auto& e : f.extras) {
      std::vector<Vec2> poly;
      for (const Vec2& p : e) poly.push_back(s.at({u + p.x, p.y}));
      // The arcade's pillars carry its ground floor; the wall behind them shows above.
      const double pillar_h = SurfaceTexture({look.id, SurfaceKind::Facade, 0.f}).groundFloorHeight();
      addPolygon(out, poly, {look.id, SurfaceKind::Pillar, static_cast<float>(pillar_h)});
    }
    u += w;
  }
}

// Trees, lamp posts and parked cars on the sidewalk and parking lane beside one block side.
void buildFurniture(const StreetGrid& g, const SideFrame& s, double length, Rng& rng, int i, int j, int k,
                    std::vector<Segment>& out) {
  const auto& o = g.options();
  const double sw = g.sidewalkWidth(), pk = g.parkingWidth();
  int n = 0;
  auto look = [&](SurfaceKind kind) {
    return makeLook(hash64(g.seed(), kTagFurnitureLook, i, j, k * 65536 + n++), kind);
  };
  if (o.tree_spacing_m > 0 && rng.chance(o.tree_probability)) {
    for (double u = 4.0 + rng.uniform(0, o.tree_spacing_m); u < length - 4.0;
         u += o.tree_spacing_m * rng.uniform(0.7, 1.3))
      addCircle(out, s.at({u, -0.6 * sw}), rng.uniform(0.15, 0.35), 6, look(SurfaceKind::Tree));
  }
  if (o.lamp_post_spacing_m > 0) {
    for (double u = 3.0 + rng.uniform(0, o.lamp_post_spacing_m); u < length - 3.0; u += o.lamp_post_spacing_m) {
      const Vec2 c = s.at({u, -0.85 * sw});
      addPolygon(out, {{c.x - 0.1, c.y - 0.1}, {c.x + 0.1, c.y - 0.1}, {c.x + 0.1, c.y + 0.1}, {c.x - 0.1, c.y + 0.1}},
                 look(SurfaceKind::LampPost));
    }
  }
  if (o.parked_car_probability > 0) {
    const double heading = std::atan2(s.u.y, s.u.x);
    for (double u = 5.0; u + 5.0 < length - 5.0; u += 6.0) {
      if (!rng.chance(o.parked_car_probability)) continue;
      const double len = rng.uniform(3.8, 4.9), wid = rng.uniform(1.6, 1.9);
      addRectangle(out, s.at({u + 2.5 + rng.uniform(-0.4, 0.4), -sw - pk / 2 + rng.uniform(-0.1, 0.1)}), heading,
                   len, wid, look(SurfaceKind::ParkedCar));
    }
  }
}

// Open space: a park of trees, or a paved square with a fountain and lamp posts.
void buildPark(const Box& b, Rng& rng, uint64_t look_seed, std::vector<Segment>& out) {
  int n = 0;
  auto look = [&](SurfaceKind kind) { return makeLook(hash64(look_seed, kTagParkLook, n++), kind); };
  if (rng.chance(0.5)) {
    for (double x = b.x0 + 6; x < b.x1 - 4; x += rng.uniform(7, 12))
      for (double y = b.y0 + 6; y < b.y1 - 4; y += rng.uniform(7, 12))
        if (rng.chance(0.6)) {
          const Vec2 c{x + rng.uniform(-2, 2), y + rng.uniform(-2, 2)};
          addCircle(out, c, rng.uniform(0.15, 0.4), 6, look(SurfaceKind::Tree));
        }
  } else {
    addCircle(out, {(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2}, rng.uniform(2.0, 5.0), 12, look(SurfaceKind::Fountain));
    for (double x = b.x0 + 5; x < b.x1 - 4; x += 15)
      for (double y : {b.y0 + 5, b.y1 - 5})
        addPolygon(out, {{x - 0.1, y - 0.1}, {x + 0.1, y - 0.1}, {x + 0.1, y + 0.1}, {x - 0.1, y + 0.1}},
                   look(SurfaceKind::LampPost));
  }
}

}  // namespace

void generateBlock(const StreetGrid& g, int i, int j, std::vector<Segment>& out) {
  const Box b = g.block(i, j);
  if (b.x1 <= b.x0 || b.y1 <= b.y0) return;
  // Counter-clockwise sides: bottom, right, top, left; v points into the block.
  const SideFrame sides[4] = {{{b.x0, b.y0}, {1, 0}, {0, 1}},
                              {{b.x1, b.y0}, {0, 1}, {-1, 0}},
                              {{b.x1, b.y1}, {-1, 0}, {0, -1}},
                              {{b.x0, b.y1}, {0, -1}, {1, 0}}};
  const double lengths[4] = {b.x1 - b.x0, b.y1 - b.y0, b.x1 - b.x0, b.y1 - b.y0};
  if (g.isPark(i, j)) {
    Rng rng(hash64(g.seed(), kTagPark, i, j));
    buildPark(b, rng, hash64(g.seed(), kTagParkLook, i, j), out);
  } else {
    std::vector<OutlineVertex> outline;
    for (int k = 0; k < 4; ++k) {
      Rng rng(hash64(g.seed(), kTagSide, i, j, k));
      buildSide(g, sides[k], lengths[k], rng, i, j, k, outline, out);
    }
    addOutline(out, outline);
  }
  for (int k = 0; k < 4; ++k) {
    Rng rng(hash64(g.seed(), kTagFurniture, i, j, k));
    buildFurniture(g, sides[k], lengths[k], rng, i, j, k, out);
  }
}

void generateDeadEnd(const StreetGrid& g, int axis, int i, int j, std::vector<Segment>& out) {
  const double h = g.streetWidth() / 2;
  const Vec2 a = g.node({i, j}), b = g.node({axis == 0 ? i + 1 : i, axis == 1 ? j + 1 : j});
  // Along the piece, between the facades of the cross streets at both ends.
  const double s0 = (axis == 0 ? a.x : a.y) + h, s1 = (axis == 0 ? b.x : b.y) - h, mid = (s0 + s1) / 2;
  const double lo = g.deadEndClosedAtEnd(axis, i, j) ? mid : s0, hi = g.deadEndClosedAtEnd(axis, i, j) ? s1 : mid;
  const double c = axis == 0 ? a.y : a.x;
  const SurfaceLook look = makeLook(hash64(g.seed(), kTagDeadEndLook, axis, i, j), SurfaceKind::Barrier);
  if (axis == 0) addPolygon(out, {{lo, c - h}, {hi, c - h}, {hi, c + h}, {lo, c + h}}, look);
  else addPolygon(out, {{c - h, lo}, {c + h, lo}, {c + h, hi}, {c - h, hi}}, look);
}

}  // namespace urbanslam::sim
