// The street network beyond the plain grid: diagonal avenues, roundabouts, several buildings per
// block. Checked by brute force over a small city: the street graph against the avenue's
// corridor, every building wall against every street's carriageway, a drive against every wall,
// and the direction a roundabout is driven.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <iostream>
#include <map>
#include <optional>
#include <tuple>
#include <set>

#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/Driver.h"

using namespace urbanslam;
using namespace urbanslam::sim;

namespace {

CityOptions networkCity(int seed = 5) {
  CityOptions o;
  o.seed = seed;
  o.area_km2 = 0.6;
  o.avenue_spacing_m = 400;
  o.roundabout_probability = 0.25;
  o.cache_tiles = 16;
  return o;
}

double pointSegment(Vec2 p, const Segment& s) {
  const Vec2 e = s.b - s.a;
  const double t = std::clamp(dot(p - s.a, e) / std::max(1e-12, dot(e, e)), 0.0, 1.0);
  return norm(p - (s.a + t * e));
}

bool isBuilding(const Segment& s) {
  return s.look.kind == SurfaceKind::Facade || s.look.kind == SurfaceKind::Featureless || s.look.kind == SurfaceKind::Pillar;
}

struct NodeLess {
  bool operator()(const NodeId& a, const NodeId& b) const { return std::tie(a.kind, a.i, a.j) < std::tie(b.kind, b.i, b.j); }
};

// Every intersection reachable from the city's centre.
std::set<NodeId, NodeLess> reachable(const StreetGrid& g) {
  std::set<NodeId, NodeLess> seen;
  std::vector<NodeId> todo{{g.lineCount() / 2, g.lineCount() / 2}};
  while (!todo.empty()) {
    const NodeId n = todo.back();
    todo.pop_back();
    if (!seen.insert(n).second) continue;
    for (const NodeId& m : g.neighbours(n)) todo.push_back(m);
  }
  return seen;
}

}  // namespace

TEST(StreetNetwork, AvenuePiecesLieInTheirCorridorAndTheGraphIsSymmetric) {
  const StreetGrid g(networkCity());
  ASSERT_TRUE(g.hasAvenues());
  const auto nodes = reachable(g);
  // The avenue's angle, from the grid's own description of it: 30..60 degrees off both axes.
  const Vec2 u = g.avenueDirection();
  EXPECT_GE(std::fabs(u.x), std::cos(60.5 * M_PI / 180));
  EXPECT_GE(std::fabs(u.y), std::cos(60.5 * M_PI / 180));
  size_t avenue_pieces = 0, crossings = 0;
  std::set<int> avenues;
  for (const NodeId& n : nodes) {
    crossings += n.kind != 0;
    const auto nb = g.neighbours(n);
    const int last = g.lineCount() - 1;
    const bool corner = n.kind == 0 && (n.i == 0 || n.i == last) && (n.j == 0 || n.j == last);
    EXPECT_GE(nb.size(), corner ? 2u : 3u) << n.i << "," << n.j << "," << n.kind;
    for (const NodeId& m : nb) {
      const auto back = g.neighbours(m);
      EXPECT_NE(std::find(back.begin(), back.end(), n), back.end()) << "one-way piece";
      const Vec2 a = g.node(n), b = g.node(m);
      EXPECT_GT(norm(b - a), 1.0);
      if (a.x == b.x || a.y == b.y) continue;  // a grid street
      ++avenue_pieces;
      // The driving lane along the piece stays inside one avenue's carriageway: nearest avenue of
      // the midpoint, then every point of the lane checked against it.
      const Vec2 mid = 0.5 * (a + b);
      const int av = static_cast<int>(std::lround((dot(mid, g.avenueNormal()) - g.avenueOffset(0)) / g.options().avenue_spacing_m));
      avenues.insert(av);
      const Vec2 d = (1.0 / norm(b - a)) * (b - a);
      // Parallel to the avenue.
      EXPECT_GT(std::fabs(dot(d, u)), std::cos(5 * M_PI / 180));
      const double lane = g.pieceLaneOffset(n, m);
      const double kerb = g.avenueHalfWidth() - g.sidewalkWidth();
      for (double t = 0; t <= 1.0; t += 0.05) {
        const Vec2 p = a + t * (b - a) + lane * Vec2{d.y, -d.x};
        EXPECT_LT(std::fabs(g.avenueDistance(av, p)) + 1.0, kerb);  // car half width 1 m
      }
    }
  }
  EXPECT_GT(crossings, 5u);
  EXPECT_GT(avenue_pieces, 10u);
  EXPECT_GE(avenues.size(), 1u);
}

TEST(StreetNetwork, NoBuildingStandsInAnyStreetAvenueOrRoundabout) {
  const CityOptions o = networkCity();
  const CityModel city(o);
  const StreetGrid& g = city.streets();
  const Box c = g.cityBox();
  const auto segs = city.segmentsNear({c.x0 - 50, c.y0 - 50, c.x1 + 50, c.y1 + 50});
  // Carriageways of the grid's streets, the avenues' strips inside the city, roundabout rings.
  const double rw = g.roadwayHalfWidth();
  std::vector<Box> streets;
  for (int l = 0; l < g.lineCount(); ++l) {
    streets.push_back({g.linePos(0, l) - rw, c.y0 - rw, g.linePos(0, l) + rw, c.y1 + rw});
    streets.push_back({c.x0 - rw, g.linePos(1, l) - rw, c.x1 + rw, g.linePos(1, l) + rw});
  }
  int a0, a1;
  g.avenuesNear(c, 0, a0, a1);
  ASSERT_LE(a0, a1);
  std::vector<Vec2> roundabouts;
  for (int i = 0; i < g.lineCount(); ++i)
    for (int j = 0; j < g.lineCount(); ++j)
      if (g.isRoundabout({i, j})) roundabouts.push_back(g.node({i, j}));
  ASSERT_GE(roundabouts.size(), 2u);
  size_t buildings = 0, cut = 0;
  const double eps = 1e-6;
  for (const Segment& s : segs) {
    if (!isBuilding(s)) continue;
    ++buildings;
    Segment clipped;
    for (const Box& b : streets) ASSERT_FALSE(clipSegment(s, b, clipped)) << s.a.x << "," << s.a.y;
    if (clipSegment(s, c, clipped))
      for (int a = a0; a <= a1; ++a) {
        const double da = g.avenueDistance(a, clipped.a), db = g.avenueDistance(a, clipped.b);
        const bool crosses = std::min(da, db) < g.avenueHalfWidth() - eps && std::max(da, db) > -g.avenueHalfWidth() + eps;
        ASSERT_FALSE(crosses) << "avenue " << a << " at " << s.a.x << "," << s.a.y;
        cut += std::fabs(da) < g.avenueHalfWidth() + 0.01 && std::fabs(db) < g.avenueHalfWidth() + 0.01;
      }
    for (const Vec2& r : roundabouts) ASSERT_GT(pointSegment(r, s), g.roundaboutClearRadius() - eps);
  }
  EXPECT_GT(buildings, 1000u);
  EXPECT_GT(cut, 20u);  // facades along the avenue (cut faces)
}

TEST(StreetNetwork, BlocksHoldSeveralBuildingsWithAlleysBetween) {
  const StreetGrid g(networkCity());
  const auto& o = g.options();
  // Outlines are closed loops: count them on a few blocks by following segment ends.
  size_t blocks = 0, several = 0;
  for (int i = 1; i < g.lineCount() - 2; ++i)
    for (int j = 1; j < g.lineCount() - 2; ++j) {
      if (g.isPark(i, j) || g.isSquare(i, j)) continue;
      std::vector<Segment> segs;
      CityModel city(o);
      const Box b = g.block(i, j);
      for (const Segment& s : city.segmentsNear(b))
        if (isBuilding(s) && s.look.kind != SurfaceKind::Pillar && b.contains(s.a) && b.contains(s.b)) segs.push_back(s);
      // Loops: a segment's end is the next one's start.
      std::multiset<std::pair<double, double>> starts;
      for (const Segment& s : segs) starts.insert({s.a.x, s.a.y});
      std::vector<bool> used(segs.size(), false);
      int loops = 0;
      for (size_t k = 0; k < segs.size(); ++k) {
        if (used[k]) continue;
        ++loops;
        size_t cur = k;
        while (!used[cur]) {
          used[cur] = true;
          for (size_t m = 0; m < segs.size(); ++m)
            if (!used[m] && segs[m].a.x == segs[cur].b.x && segs[m].a.y == segs[cur].b.y) {
              cur = m;
              break;
            }
        }
      }
      ++blocks;
      several += loops >= 2;
    }
  ASSERT_GT(blocks, 5u);
  EXPECT_GT(several, blocks * 8 / 10);
}

TEST(Driver, StaysClearOfEveryWallOnAvenuesAndDrivesRoundaboutsCounterClockwise) {
  SimOptions o;
  o.city = networkCity();
  o.route.route_length_km = 5.0;
  o.route.revisit_probability = 0.6;  // a drive that explores more: it reaches the avenue
  const CityModel city(o.city);
  const StreetGrid& g = city.streets();
  Driver d(g, o);
  double t = 0, worst = 1e9, on_avenue_m = 0;
  Vec2 last{d.state().pose.x, d.state().pose.y};
  // A roundabout pass: the polar sweep about its centre while on the ring.
  struct Pass {
    Vec2 centre;
    double sweep = 0, last_polar = 0;
  };
  std::optional<Pass> pass;
  std::vector<Pass> passes;
  while (!d.finished() && t < 2000) {
    t += 0.05;
    d.advanceTo(t);
    const auto& s = d.state();
    const Vec2 p{s.pose.x, s.pose.y};
    for (const Segment& w : city.segmentsNear({p.x - 5, p.y - 5, p.x + 5, p.y + 5})) {
      const double dist = pointSegment(p, w);
      worst = std::min(worst, dist);
      ASSERT_GT(dist, 1.0) << "t " << t << " at " << p.x << "," << p.y << " kind " << static_cast<int>(w.look.kind);
    }
    // On an avenue, away from the grid's streets.
    const double dx = std::min(p.x - g.linePos(0, g.lineBelow(0, p.x)), g.linePos(0, g.lineBelow(0, p.x) + 1) - p.x);
    const double dy = std::min(p.y - g.linePos(1, g.lineBelow(1, p.y)), g.linePos(1, g.lineBelow(1, p.y) + 1) - p.y);
    if (g.inAvenue(p) && std::min(dx, dy) > g.streetWidth()) on_avenue_m += norm(p - last);
    last = p;
    const bool on_ring = g.nearRoundabout(p, g.ringRadius() + 1.0);
    if (on_ring) {
      if (!pass) {
        int i = g.lineBelow(0, p.x), j = g.lineBelow(1, p.y);
        if (g.linePos(0, i + 1) - p.x < p.x - g.linePos(0, i)) ++i;
        if (g.linePos(1, j + 1) - p.y < p.y - g.linePos(1, j)) ++j;
        pass = Pass{g.node({i, j})};
        pass->last_polar = std::atan2(p.y - pass->centre.y, p.x - pass->centre.x);
      }
      const double polar = std::atan2(p.y - pass->centre.y, p.x - pass->centre.x);
      pass->sweep += common::wrapToPi(polar - pass->last_polar);
      pass->last_polar = polar;
    } else if (pass) {
      passes.push_back(*pass);
      pass.reset();
    }
  }
  EXPECT_TRUE(d.finished());
  EXPECT_GT(on_avenue_m, 200.0);
  ASSERT_GE(passes.size(), 3u);
  // Counter-clockwise round the island: the position's angle about the centre grows. (The
  // heading's net change is the exit's direction: negative when the car leaves to the right.)
  for (const Pass& p : passes) EXPECT_GT(p.sweep, 0.3) << "roundabout at " << p.centre.x << "," << p.centre.y;
  std::cout << "closest wall " << worst << " m, " << on_avenue_m << " m on avenues, " << passes.size() << " roundabout passes\n";
}

TEST(CityModel, TilesWithAvenuesAndRoundaboutsAreIdenticalInAnyBuildOrder) {
  const CityOptions o = networkCity();
  const CityModel a(o), b(o);
  const Box c = a.streets().cityBox();
  const int tx0 = a.tileOf(c.x0) - 1, tx1 = a.tileOf(c.x1) + 1, ty0 = a.tileOf(c.y0) - 1, ty1 = a.tileOf(c.y1) + 1;
  // a: row by row; b: the other way round, so most tiles are built after their neighbours, and
  // with a cache too small to keep them (rebuilt below).
  std::map<std::pair<int, int>, std::vector<Segment>> first;
  for (int tx = tx0; tx <= tx1; ++tx)
    for (int ty = ty0; ty <= ty1; ++ty) first[{tx, ty}] = a.tile(tx, ty)->segments;
  for (int tx = tx1; tx >= tx0; --tx)
    for (int ty = ty1; ty >= ty0; --ty) b.tile(tx, ty);
  size_t total = 0;
  for (const auto& [key, segs] : first) {
    const auto t = b.tile(key.first, key.second);
    ASSERT_EQ(segs.size(), t->segments.size()) << key.first << "," << key.second;
    for (size_t k = 0; k < segs.size(); ++k) {
      ASSERT_EQ(segs[k].a.x, t->segments[k].a.x);
      ASSERT_EQ(segs[k].a.y, t->segments[k].a.y);
      ASSERT_EQ(segs[k].b.x, t->segments[k].b.x);
      ASSERT_EQ(segs[k].b.y, t->segments[k].b.y);
      ASSERT_EQ(segs[k].look.id, t->segments[k].look.id);
      ASSERT_EQ(segs[k].u0_m, t->segments[k].u0_m);
    }
    total += segs.size();
    // Locality (up to the rounding of clipping an oblique cut face at the tile's edge).
    const Box grown{t->box.x0 - 1e-9, t->box.y0 - 1e-9, t->box.x1 + 1e-9, t->box.y1 + 1e-9};
    for (const Segment& s : segs)
      for (Vec2 p : {s.a, s.b}) ASSERT_TRUE(grown.contains(p)) << p.x << "," << p.y;
  }
  EXPECT_GT(total, 10000u);
  EXPECT_GT(b.tilesBuilt(), first.size());  // b really rebuilt evicted tiles
}
