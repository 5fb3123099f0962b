#include "urbanslam/sim/BlockGenerator.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Random.h"
#include "urbanslam/sim/SurfaceTexture.h"

namespace urbanslam::sim {

namespace {

constexpr uint64_t kTagSide = 10, kTagDesign = 11, kTagPark = 12, kTagFurniture = 13, kTagLots = 19, kTagSquare = 20;
// Looks are drawn from hashes of their own, never from the geometry's generators: the camera's
// attributes leave the walls the laser sees exactly as they were.
constexpr uint64_t kTagLook = 14, kTagDesignLook = 15, kTagFurnitureLook = 16, kTagParkLook = 17, kTagDeadEndLook = 18, kTagCutLook = 21,
                   kTagIslandLook = 22, kTagCutDetail = 23, kTagAvenueTree = 24;

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

// A free-standing object (pillar, tree, post, parked car, bench, fountain) as a closed polygon.
struct Object {
  std::vector<Vec2> poly;
  SurfaceLook look;
};

Object circleObject(Vec2 c, double r, int sides, const SurfaceLook& look) {
  Object o{{}, look};
  for (int k = 0; k < sides; ++k) {
    const double a = 2 * M_PI * k / sides;
    o.poly.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  return o;
}

Object rectObject(Vec2 c, double heading, double l, double w, const SurfaceLook& look) {
  const Vec2 f{std::cos(heading) * l / 2, std::sin(heading) * l / 2}, s{-std::sin(heading) * w / 2, std::cos(heading) * w / 2};
  return {{c + f + s, c - f + s, c - f - s, c + f - s}, look};
}

// Objects standing in an avenue's carriageway or a roundabout's ring are left out: those were
// laid out for the grid's streets and blocks, which the avenues and roundabouts cut.
void addObjects(const StreetGrid& g, const std::vector<Object>& objects, std::vector<Segment>& out) {
  const double ring = g.roundaboutClearRadius();
  for (const Object& o : objects) {
    bool blocked = false;
    for (const Vec2& p : o.poly) blocked = blocked || g.inAvenue(p, 0.3) || g.nearRoundabout(p, ring + 0.3);
    if (!blocked) addPolygon(out, o.poly, o.look);
  }
}

void addOutline(std::vector<Segment>& out, const std::vector<OutlineVertex>& v) {
  for (size_t i = 0; i < v.size(); ++i) out.push_back({v[i].p, v[(i + 1) % v.size()].p, v[i].look, static_cast<float>(v[i].u)});
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
void buildSide(const StreetGrid& g, const SideFrame& s, double length, Rng& rng, int i, int j, int k, std::vector<OutlineVertex>& outline,
               std::vector<Object>& objects) {
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
      objects.push_back({poly, {look.id, SurfaceKind::Pillar, static_cast<float>(pillar_h)}});
    }
    u += w;
  }
}

// Trees, lamp posts and parked cars on the sidewalk and parking lane beside one block side.
void buildFurniture(const StreetGrid& g, const SideFrame& s, double length, Rng& rng, int i, int j, int k, std::vector<Object>& out) {
  const auto& o = g.options();
  const double sw = g.sidewalkWidth(), pk = g.parkingWidth();
  int n = 0;
  auto look = [&](SurfaceKind kind) { return makeLook(hash64(g.seed(), kTagFurnitureLook, i, j, k * 65536 + n++), kind); };
  if (o.tree_spacing_m > 0 && rng.chance(o.tree_probability)) {
    for (double u = 4.0 + rng.uniform(0, o.tree_spacing_m); u < length - 4.0; u += o.tree_spacing_m * rng.uniform(0.7, 1.3))
      out.push_back(circleObject(s.at({u, -0.6 * sw}), rng.uniform(0.15, 0.35), 6, look(SurfaceKind::Tree)));
  }
  if (o.lamp_post_spacing_m > 0) {
    for (double u = 3.0 + rng.uniform(0, o.lamp_post_spacing_m); u < length - 3.0; u += o.lamp_post_spacing_m) {
      out.push_back(rectObject(s.at({u, -0.85 * sw}), 0.0, 0.2, 0.2, look(SurfaceKind::LampPost)));
    }
  }
  if (o.parked_car_probability > 0) {
    const double heading = std::atan2(s.u.y, s.u.x);
    for (double u = 5.0; u + 5.0 < length - 5.0; u += 6.0) {
      if (!rng.chance(o.parked_car_probability)) continue;
      const double len = rng.uniform(3.8, 4.9), wid = rng.uniform(1.6, 1.9);
      out.push_back(rectObject(s.at({u + 2.5 + rng.uniform(-0.4, 0.4), -sw - pk / 2 + rng.uniform(-0.1, 0.1)}), heading, len, wid,
                               look(SurfaceKind::ParkedCar)));
    }
  }
}

// A park: trees at random in a loose grid.
void buildPark(const Box& b, Rng& rng, uint64_t look_seed, std::vector<Object>& out) {
  int n = 0;
  auto look = [&](SurfaceKind kind) { return makeLook(hash64(look_seed, kTagParkLook, n++), kind); };
  for (double x = b.x0 + 6; x < b.x1 - 4; x += rng.uniform(7, 12))
    for (double y = b.y0 + 6; y < b.y1 - 4; y += rng.uniform(7, 12))
      if (rng.chance(0.6)) {
        const Vec2 c{x + rng.uniform(-2, 2), y + rng.uniform(-2, 2)};
        out.push_back(circleObject(c, rng.uniform(0.15, 0.4), 6, look(SurfaceKind::Tree)));
      }
}

// A paved square: a fountain in the middle, a ring of benches round it, lamp posts along its
// edges and a few trees in its corners. Mostly open: the laser sees far across it.
void buildSquare(const Box& b, Rng& rng, uint64_t look_seed, std::vector<Object>& out) {
  int n = 0;
  auto look = [&](SurfaceKind kind) { return makeLook(hash64(look_seed, kTagParkLook, n++), kind); };
  const Vec2 c{(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2};
  const double r = rng.uniform(2.0, std::min(6.0, 0.15 * std::min(b.x1 - b.x0, b.y1 - b.y0)));
  out.push_back(circleObject(c, r, 12, look(SurfaceKind::Fountain)));
  const int benches = rng.uniformInt(4, 8);
  const double ring = r + rng.uniform(4.0, 7.0), a0 = rng.uniform(0, 2 * M_PI);
  for (int k = 0; k < benches; ++k) {
    const double a = a0 + 2 * M_PI * k / benches;
    out.push_back(rectObject(c + Vec2{ring * std::cos(a), ring * std::sin(a)}, a + M_PI / 2, 1.8, 0.5, look(SurfaceKind::Bench)));
  }
  const double step = rng.uniform(12.0, 20.0);
  for (double x = b.x0 + 4; x < b.x1 - 3; x += step)
    for (double y : {b.y0 + 4, b.y1 - 4}) out.push_back(rectObject({x, y}, 0.0, 0.2, 0.2, look(SurfaceKind::LampPost)));
  for (double y = b.y0 + 4 + step; y < b.y1 - 3 - step / 2; y += step)
    for (double x : {b.x0 + 4, b.x1 - 4}) out.push_back(rectObject({x, y}, 0.0, 0.2, 0.2, look(SurfaceKind::LampPost)));
  for (Vec2 corner : {Vec2{b.x0 + 9, b.y0 + 9}, Vec2{b.x1 - 9, b.y0 + 9}, Vec2{b.x0 + 9, b.y1 - 9}, Vec2{b.x1 - 9, b.y1 - 9}})
    if (rng.chance(0.5)) out.push_back(circleObject(corner, rng.uniform(0.2, 0.4), 6, look(SurfaceKind::Tree)));
}

// Keeps the part of a closed outline where dot(p, n) >= c (Sutherland-Hodgman). Every vertex
// carries the look of the segment it starts: the cut faces get `cut`, what is left of a facade
// keeps its look and texture coordinate.
std::vector<OutlineVertex> clipOutline(const std::vector<OutlineVertex>& v, Vec2 n, double c, const SurfaceLook& cut) {
  std::vector<OutlineVertex> out;
  for (size_t k = 0; k < v.size(); ++k) {
    const OutlineVertex& a = v[k];
    const OutlineVertex& b = v[(k + 1) % v.size()];
    const double fa = dot(a.p, n) - c, fb = dot(b.p, n) - c;
    if (fa >= 0) out.push_back(a);
    if ((fa >= 0) != (fb >= 0)) {
      const double t = fa / (fa - fb);
      const Vec2 p = a.p + t * (b.p - a.p);
      if (fa >= 0)
        out.push_back({p, cut, 0.0});
      else
        out.push_back({p, a.look, a.u + t * norm(b.p - a.p)});
    }
  }
  return out;
}

double outlineArea(const std::vector<OutlineVertex>& v) {
  double a = 0;
  for (size_t k = 0; k < v.size(); ++k) a += cross(v[k].p, v[(k + 1) % v.size()].p);
  return std::fabs(a) / 2;
}

// Whether a look is one of the cut faces cutBuilding gave building q of block (i, j).
bool isCutLook(const SurfaceLook& look, const StreetGrid& g, int i, int j, int q, int cuts) {
  for (int n = 0; n < cuts; ++n)
    if (look.id == lookId(hash64(g.seed(), kTagCutLook, i, j, q * 64 + n))) return true;
  return false;
}

// A building's outline, cut back where a roundabout's ring (at a corner of the block) or a
// diagonal avenue (across it) needs the room: the pieces that are left.
std::vector<std::vector<OutlineVertex>> cutBuilding(const StreetGrid& g, int i, int j, int q, std::vector<OutlineVertex> outline) {
  std::vector<std::vector<OutlineVertex>> pieces;
  int cut_n = 0;
  auto cutLook = [&]() { return makeLook(hash64(g.seed(), kTagCutLook, i, j, q * 64 + cut_n++), SurfaceKind::Facade); };
  // Roundabouts: a chamfer across the block's corner, tangent to the clear circle.
  for (int di = 0; di < 2; ++di)
    for (int dj = 0; dj < 2; ++dj) {
      const NodeId corner{i + di, j + dj};
      if (!g.isRoundabout(corner)) continue;
      const Vec2 dir = (1.0 / std::sqrt(2.0)) * Vec2{di ? -1.0 : 1.0, dj ? -1.0 : 1.0};  // into the block
      outline = clipOutline(outline, dir, dot(g.node(corner), dir) + g.roundaboutClearRadius(), cutLook());
      if (outline.size() < 3) return pieces;
    }
  pieces.push_back(std::move(outline));
  // Avenues: the parts on either side of the avenue's strip.
  if (g.hasAvenues() && g.blockInCity(i, j)) {
    const Box b = g.block(i, j);
    int a0, a1;
    g.avenuesNear(b, g.avenueHalfWidth(), a0, a1);
    const Vec2 nv = g.avenueNormal();
    for (int a = a0; a <= a1; ++a) {
      std::vector<std::vector<OutlineVertex>> next;
      const double off = g.avenueOffset(a), h = g.avenueHalfWidth();
      for (const auto& p : pieces) {
        auto left = clipOutline(p, nv, off + h, cutLook());
        auto right = clipOutline(p, -1.0 * nv, -(off - h), cutLook());
        if (left.size() >= 3) next.push_back(std::move(left));
        if (right.size() >= 3) next.push_back(std::move(right));
      }
      pieces = std::move(next);
    }
  }
  // The cut faces get doorway recesses like any facade: a long plain wall on both sides of an
  // avenue would be a corridor in which a laser cannot tell how far along it is.
  std::vector<std::vector<OutlineVertex>> kept;
  int piece_n = 0;
  for (auto& p : pieces) {
    if (outlineArea(p) <= 8.0) continue;
    Rng rng(hash64(g.seed(), kTagCutDetail, i, j, q * 64 + piece_n++));
    std::vector<OutlineVertex> v;
    for (size_t k = 0; k < p.size(); ++k) {
      const OutlineVertex& a = p[k];
      const Vec2 b = p[(k + 1) % p.size()].p;
      v.push_back(a);
      const double len = norm(b - a.p);
      if (a.look.kind != SurfaceKind::Facade || a.u != 0.0 || len < 6.0 || !isCutLook(a.look, g, i, j, q, cut_n)) continue;
      const Vec2 dir = (1.0 / len) * (b - a.p), in{-dir.y, dir.x};  // outlines run counter-clockwise
      double extra = 0;                                             // texture coordinate gained in the recesses so far
      for (double u = rng.uniform(1.5, 3.5);;) {
        const double w = rng.uniform(1.2, 2.8), depth = rng.uniform(0.3, 0.8);
        if (u + w > len - 1.0) break;
        if (rng.chance(0.6)) {
          auto at = [&](double x, double y) { return a.p + x * dir + y * in; };
          v.push_back({at(u, 0), a.look, u + extra});
          v.push_back({at(u, depth), a.look, u + extra + depth});
          v.push_back({at(u + w, depth), a.look, u + w + extra + depth});
          extra += 2 * depth;
          v.push_back({at(u + w, 0), a.look, u + w + extra});
        }
        u += w + rng.uniform(1.0, 5.0);
      }
    }
    kept.push_back(std::move(v));
  }
  return kept;
}

// Several buildings on the block, in one or two rows along its longer side with alleys
// between them; some stand back from the street.
void buildBuildings(const StreetGrid& g, int i, int j, std::vector<Segment>& out, std::vector<Object>& objects) {
  const auto& o = g.options();
  const Box b = g.block(i, j);
  Rng rng(hash64(g.seed(), kTagLots, i, j));
  const int count = rng.uniformInt(o.buildings_per_block_min, std::max(o.buildings_per_block_min, o.buildings_per_block_max));
  const bool along_x = b.x1 - b.x0 >= b.y1 - b.y0;
  const double long_len = along_x ? b.x1 - b.x0 : b.y1 - b.y0, short_len = along_x ? b.y1 - b.y0 : b.x1 - b.x0;
  const double alley = o.alley_width_m, min_lot = 10.0;
  const int rows = count >= 4 && short_len >= 2 * 20.0 + alley ? 2 : 1;
  std::vector<std::pair<double, double>> row_spans;
  if (rows == 1) {
    row_spans.push_back({0, short_len});
  } else {
    const double split = short_len * rng.uniform(0.4, 0.6);
    row_spans = {{0, split - alley / 2}, {split + alley / 2, short_len}};
  }
  std::vector<Box> lots;
  for (int r = 0; r < rows; ++r) {
    int cols = rows == 1 ? count : (r == 0 ? (count + 1) / 2 : count / 2);
    cols = std::max(1, std::min(cols, static_cast<int>((long_len + alley) / (min_lot + alley))));
    std::vector<double> w(cols);
    double total = 0;
    for (double& x : w) total += (x = rng.uniform(0.6, 1.4));
    double u = 0;
    for (int c = 0; c < cols; ++c) {
      const double len = (long_len - (cols - 1) * alley) * w[c] / total;
      const double u1 = c + 1 == cols ? long_len : u + len;
      const auto [v0, v1] = row_spans[r];
      lots.push_back(along_x ? Box{b.x0 + u, b.y0 + v0, b.x0 + u1, b.y0 + v1} : Box{b.x0 + v0, b.y0 + u, b.x0 + v1, b.y0 + u1});
      u = u1 + alley;
    }
  }
  for (int q = 0; q < static_cast<int>(lots.size()); ++q) {
    Box l = lots[q];
    // Standing back from the street: only the sides on the block's edge move.
    if (o.building_setback_max_m > 0 && rng.chance(0.3)) {
      const double s = rng.uniform(0.5, o.building_setback_max_m);
      if (l.x0 == b.x0) l.x0 += s;
      if (l.x1 == b.x1) l.x1 -= s;
      if (l.y0 == b.y0) l.y0 += s;
      if (l.y1 == b.y1) l.y1 -= s;
    }
    if (l.x1 - l.x0 < 4.0 || l.y1 - l.y0 < 4.0) continue;
    // Counter-clockwise sides: bottom, right, top, left; v points into the building.
    const SideFrame sides[4] = {
        {{l.x0, l.y0}, {1, 0}, {0, 1}}, {{l.x1, l.y0}, {0, 1}, {-1, 0}}, {{l.x1, l.y1}, {-1, 0}, {0, -1}}, {{l.x0, l.y1}, {0, -1}, {1, 0}}};
    const double lengths[4] = {l.x1 - l.x0, l.y1 - l.y0, l.x1 - l.x0, l.y1 - l.y0};
    std::vector<OutlineVertex> outline;
    for (int k = 0; k < 4; ++k) {
      Rng side_rng(hash64(g.seed(), kTagSide, i, j, q * 4 + k));
      buildSide(g, sides[k], lengths[k], side_rng, i, j, q * 4 + k, outline, objects);
    }
    for (const auto& piece : cutBuilding(g, i, j, q, std::move(outline))) addOutline(out, piece);
  }
}

}  // namespace

void generateBlock(const StreetGrid& g, int i, int j, std::vector<Segment>& out) {
  const Box b = g.block(i, j);
  if (b.x1 <= b.x0 || b.y1 <= b.y0) return;
  std::vector<Object> objects;
  if (g.isPark(i, j)) {
    Rng rng(hash64(g.seed(), kTagPark, i, j));
    buildPark(b, rng, hash64(g.seed(), kTagParkLook, i, j), objects);
  } else if (g.isSquare(i, j)) {
    Rng rng(hash64(g.seed(), kTagSquare, i, j));
    buildSquare(b, rng, hash64(g.seed(), kTagParkLook, i, j), objects);
  } else {
    buildBuildings(g, i, j, out, objects);
  }
  // Sidewalk furniture along the block's four sides (counter-clockwise, v into the block).
  const SideFrame sides[4] = {
      {{b.x0, b.y0}, {1, 0}, {0, 1}}, {{b.x1, b.y0}, {0, 1}, {-1, 0}}, {{b.x1, b.y1}, {-1, 0}, {0, -1}}, {{b.x0, b.y1}, {0, -1}, {1, 0}}};
  const double lengths[4] = {b.x1 - b.x0, b.y1 - b.y0, b.x1 - b.x0, b.y1 - b.y0};
  for (int k = 0; k < 4; ++k) {
    Rng rng(hash64(g.seed(), kTagFurniture, i, j, k));
    buildFurniture(g, sides[k], lengths[k], rng, i, j, k, objects);
  }
  addObjects(g, objects, out);
  // A row of trees (now and then a lamp post) on each sidewalk of an avenue: the trees whose
  // place lies on this block's lot.
  if (g.hasAvenues() && g.blockInCity(i, j) && g.options().tree_spacing_m > 0) {
    int a0, a1;
    g.avenuesNear(b, g.avenueHalfWidth(), a0, a1);
    const Vec2 u = g.avenueDirection(), nv = g.avenueNormal();
    double t0 = 1e300, t1 = -1e300;
    for (Vec2 c : {Vec2{b.x0, b.y0}, Vec2{b.x1, b.y0}, Vec2{b.x0, b.y1}, Vec2{b.x1, b.y1}}) {
      t0 = std::min(t0, dot(c, u));
      t1 = std::max(t1, dot(c, u));
    }
    const double sp = g.options().tree_spacing_m;
    for (int a = a0; a <= a1; ++a)
      for (int side : {-1, 1}) {
        const double across = g.avenueOffset(a) + side * (g.avenueHalfWidth() - 0.6 * g.sidewalkWidth());
        for (long k = static_cast<long>(std::floor(t0 / sp)) - 1; k <= static_cast<long>(std::ceil(t1 / sp)) + 1; ++k) {
          Rng r(hash64(g.seed(), kTagAvenueTree, a * 2 + (side > 0), k));
          const Vec2 p = across * nv + (k * sp + r.uniform(-0.25, 0.25) * sp) * u;
          if (!b.contains(p)) continue;
          const SurfaceLook look = makeLook(r.next(), r.chance(0.2) ? SurfaceKind::LampPost : SurfaceKind::Tree);
          if (look.kind == SurfaceKind::LampPost)
            addRectangle(out, p, 0.0, 0.2, 0.2, look);
          else
            addCircle(out, p, r.uniform(0.2, 0.4), 6, look);
        }
      }
  }
}

void generateRoundabout(const StreetGrid& g, NodeId n, std::vector<Segment>& out) {
  addCircle(out, g.node(n), g.islandRadius(), 20, makeLook(hash64(g.seed(), kTagIslandLook, n.i, n.j), SurfaceKind::Island));
}

void generateDeadEnd(const StreetGrid& g, int axis, int i, int j, std::vector<Segment>& out) {
  const double h = g.streetWidth() / 2;
  const Vec2 a = g.node({i, j}), b = g.node({axis == 0 ? i + 1 : i, axis == 1 ? j + 1 : j});
  // Along the piece, between the facades of the cross streets at both ends.
  const double s0 = (axis == 0 ? a.x : a.y) + h, s1 = (axis == 0 ? b.x : b.y) - h, mid = (s0 + s1) / 2;
  const double lo = g.deadEndClosedAtEnd(axis, i, j) ? mid : s0, hi = g.deadEndClosedAtEnd(axis, i, j) ? s1 : mid;
  const double c = axis == 0 ? a.y : a.x;
  const SurfaceLook look = makeLook(hash64(g.seed(), kTagDeadEndLook, axis, i, j), SurfaceKind::Barrier);
  if (axis == 0)
    addPolygon(out, {{lo, c - h}, {hi, c - h}, {hi, c + h}, {lo, c + h}}, look);
  else
    addPolygon(out, {{c - h, lo}, {c + h, lo}, {c + h, hi}, {c - h, hi}}, look);
}

}  // namespace urbanslam::sim
