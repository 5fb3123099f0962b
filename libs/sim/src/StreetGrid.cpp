#include "urbanslam/sim/StreetGrid.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "urbanslam/sim/Random.h"

namespace urbanslam::sim {

namespace {
// Tags keep the hash streams of different features apart.
constexpr uint64_t kTagLine = 1, kTagDeadEnd = 2, kTagDeadEndSide = 3, kTagPark = 4, kTagAvenue = 5, kTagRoundabout = 6;
}  // namespace

StreetGrid::StreetGrid(const CityOptions& options)
    : options_(options), seed_(static_cast<uint64_t>(options.seed)), width_(options.street_width_m) {
  // Block side = pitch - width + jitter(i+1) - jitter(i): with jitter in [-J, J] and
  // J = (max - min) / 4 every block stays within [block_min_m, block_max_m].
  pitch_ = (options.block_min_m + options.block_max_m) / 2 + width_;
  jitter_ = (options.block_max_m - options.block_min_m) / 4;
  const double side = std::sqrt(options.area_km2) * 1000.0;
  lines_ = std::max(2, static_cast<int>(std::floor(side / pitch_)) + 1);
  if (options.avenue_spacing_m > 0) {
    // One angle for all avenues, 30..60 degrees off both axes: they never meet each other, and
    // every crossing with the grid is oblique enough to be an intersection, not a merge.
    avenue_spacing_ = options.avenue_spacing_m;
    const uint64_t h = hash64(seed_, kTagAvenue);
    double angle = (30.0 + 30.0 * unitFromHash(h)) * M_PI / 180.0;
    if (h & 1) angle = M_PI - angle;
    avenue_u_ = {std::cos(angle), std::sin(angle)};
    avenue_n_ = {-avenue_u_.y, avenue_u_.x};
    avenue_phase_ = unitFromHash(hash64(seed_, kTagAvenue, 1)) * avenue_spacing_;
  }
}

double StreetGrid::linePos(int axis, int index) const {
  const double u = unitFromHash(hash64(seed_, kTagLine, axis, index));
  return index * pitch_ + (2 * u - 1) * jitter_;
}

int StreetGrid::lineBelow(int axis, double v) const {
  int i = static_cast<int>(std::floor(v / pitch_));
  while (linePos(axis, i) > v) --i;
  while (linePos(axis, i + 1) <= v) ++i;
  return i;
}

Box StreetGrid::cityBox() const { return {linePos(0, 0), linePos(1, 0), linePos(0, lines_ - 1), linePos(1, lines_ - 1)}; }

Vec2 StreetGrid::node(NodeId n) const {
  if (n.kind == 0) return {linePos(0, n.i), linePos(1, n.j)};
  Vec2 p;
  rawCrossing(n.i, n.kind - 1, n.j, p);
  return p;
}

// --- avenues ---------------------------------------------------------------------------------

void StreetGrid::avenuesNear(const Box& b, double margin, int& a0, int& a1) const {
  a0 = 1;
  a1 = 0;
  if (!hasAvenues()) return;
  double lo = 1e300, hi = -1e300;
  for (Vec2 c : {Vec2{b.x0, b.y0}, Vec2{b.x1, b.y0}, Vec2{b.x0, b.y1}, Vec2{b.x1, b.y1}}) {
    lo = std::min(lo, dot(c, avenue_n_));
    hi = std::max(hi, dot(c, avenue_n_));
  }
  a0 = static_cast<int>(std::ceil((lo - margin - avenue_phase_) / avenue_spacing_));
  a1 = static_cast<int>(std::floor((hi + margin - avenue_phase_) / avenue_spacing_));
}

bool StreetGrid::inAvenue(Vec2 p, double margin) const {
  if (!hasAvenues()) return false;
  const Box c = cityBox();
  if (p.x < c.x0 - margin || p.x > c.x1 + margin || p.y < c.y0 - margin || p.y > c.y1 + margin) return false;
  const int a = static_cast<int>(std::lround((dot(p, avenue_n_) - avenue_phase_) / avenue_spacing_));
  return std::fabs(avenueDistance(a, p)) < avenueHalfWidth() + margin;
}

bool StreetGrid::rawCrossing(int a, int axis, int l, Vec2& p) const {
  const double off = avenueOffset(a);
  if (axis == 0) {
    p.x = linePos(0, l);
    p.y = (off - avenue_n_.x * p.x) / avenue_n_.y;
  } else {
    p.y = linePos(1, l);
    p.x = (off - avenue_n_.y * p.y) / avenue_n_.x;
  }
  if (!hasAvenues() || l < 0 || l >= lines_) return false;
  const Box c = cityBox();
  return p.x >= c.x0 && p.x <= c.x1 && p.y >= c.y0 && p.y <= c.y1;
}

NodeId StreetGrid::crossingNode(int a, int axis, int l) const {
  Vec2 p;
  rawCrossing(a, axis, l, p);
  const int oa = 1 - axis;
  const double v = oa == 0 ? p.x : p.y;
  int m = lineBelow(oa, v);
  if (linePos(oa, m + 1) - v < v - linePos(oa, m)) ++m;
  const NodeId g = axis == 0 ? NodeId{l, m, 0} : NodeId{m, l, 0};
  if (inCity(g) && std::fabs(avenueDistance(a, node(g))) < mergeRadius()) return g;
  return {a, l, 1 + axis};
}

bool StreetGrid::onAvenue(int a, NodeId n) const {
  if (n.kind != 0) return n.i == a;
  if (!hasAvenues() || !inCity(n) || std::fabs(avenueDistance(a, node(n))) >= mergeRadius()) return false;
  Vec2 p;
  return (rawCrossing(a, 0, n.i, p) && crossingNode(a, 0, n.i) == n) || (rawCrossing(a, 1, n.j, p) && crossingNode(a, 1, n.j) == n);
}

bool StreetGrid::avenueStep(int a, NodeId n, int dir, NodeId& next) const {
  const double off = avenueOffset(a);
  double t0 = dot(node(n), avenue_u_);
  // Raw crossings in order along the avenue; the one or two that merge into n are skipped.
  for (int guard = 0; guard < 8; ++guard) {
    double best = 1e300;
    int best_axis = -1, best_l = 0;
    for (int axis = 0; axis < 2; ++axis) {
      const double comp = axis == 0 ? avenue_u_.x : avenue_u_.y;
      const double base = off * (axis == 0 ? avenue_n_.x : avenue_n_.y);
      const double coord = base + t0 * comp;
      const int s = dir * comp > 0 ? 1 : -1;
      int l = s > 0 ? lineBelow(axis, coord) + 1 : lineBelow(axis, coord);
      double t = 0;
      for (int k = 0; k < 4; ++k, l += s) {
        t = (linePos(axis, l) - base) / comp;
        if (dir * (t - t0) > 1e-6) break;
      }
      if (l < 0 || l >= lines_ || dir * (t - t0) <= 1e-6) continue;
      if (dir * (t - t0) < best) {
        best = dir * (t - t0);
        best_axis = axis;
        best_l = l;
      }
    }
    Vec2 p;
    if (best_axis < 0 || !rawCrossing(a, best_axis, best_l, p)) return false;  // left the city
    const NodeId c = crossingNode(a, best_axis, best_l);
    if (c == n) {
      t0 += dir * best;
      continue;
    }
    next = c;
    return true;
  }
  return false;
}

bool StreetGrid::pieceSplit(int axis, int i, int j, NodeId from, NodeId& split) const {
  if (!hasAvenues()) return false;
  const Vec2 a = node({i, j}), b = node({axis == 0 ? i + 1 : i, axis == 1 ? j + 1 : j});
  const double da = dot(a, avenue_n_), db = dot(b, avenue_n_);
  const int a0 = static_cast<int>(std::ceil((std::min(da, db) - avenue_phase_) / avenue_spacing_));
  const int a1 = static_cast<int>(std::floor((std::max(da, db) - avenue_phase_) / avenue_spacing_));
  const Vec2 f = node(from);
  double best = 1e300;
  for (int av = a0; av <= a1; ++av) {
    const int la = axis == 0 ? 1 : 0, l = axis == 0 ? j : i;
    Vec2 p;
    if (!rawCrossing(av, la, l, p)) continue;
    const NodeId c = crossingNode(av, la, l);
    if (c.kind == 0) continue;  // merged into one of the piece's ends
    if (norm(p - f) < best) {
      best = norm(p - f);
      split = c;
    }
  }
  return best < 1e300;
}

// --- grid pieces -----------------------------------------------------------------------------

bool StreetGrid::deadEndCandidate(int axis, int i, int j) const {
  // Only pieces between interior intersections; the city's edge streets stay open.
  const int i1 = axis == 0 ? i + 1 : i, j1 = axis == 1 ? j + 1 : j;
  if (i <= 0 || j <= 0 || i1 >= lines_ - 1 || j1 >= lines_ - 1) return false;
  if (unitFromHash(hash64(seed_, kTagDeadEnd, axis, i, j)) >= options_.dead_end_probability) return false;
  // Never near an avenue: its wall would close the avenue too.
  if (hasAvenues()) {
    const Vec2 a = node({i, j}), b = node({i1, j1});
    int a0, a1;
    avenuesNear({std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)}, avenueHalfWidth() + width_, a0, a1);
    if (a0 <= a1) return false;
  }
  return true;
}

EdgeState StreetGrid::edge(int axis, int i, int j) const {
  const int i1 = axis == 0 ? i + 1 : i, j1 = axis == 1 ? j + 1 : j;
  if (!inCity({i, j}) || !inCity({i1, j1})) return EdgeState::Missing;
  if (!deadEndCandidate(axis, i, j)) return EdgeState::Open;
  // A dead end only where no other piece at either end is one, so every intersection keeps at
  // least three ways out and a drive never has to turn around.
  for (NodeId n : {NodeId{i, j}, NodeId{i1, j1}}) {
    const int cand[4][3] = {{0, n.i, n.j}, {0, n.i - 1, n.j}, {1, n.i, n.j}, {1, n.i, n.j - 1}};
    for (const auto& c : cand) {
      if (c[0] == axis && c[1] == i && c[2] == j) continue;
      if (deadEndCandidate(c[0], c[1], c[2])) return EdgeState::Open;
    }
  }
  return EdgeState::DeadEnd;
}

bool StreetGrid::deadEndClosedAtEnd(int axis, int i, int j) const { return hash64(seed_, kTagDeadEndSide, axis, i, j) & 1; }

std::vector<NodeId> StreetGrid::neighbours(NodeId n) const {
  std::vector<NodeId> out;
  if (n.kind == 0) {
    const int pieces[4][3] = {{0, n.i, n.j}, {1, n.i, n.j}, {0, n.i - 1, n.j}, {1, n.i, n.j - 1}};
    const NodeId ends[4] = {{n.i + 1, n.j}, {n.i, n.j + 1}, {n.i - 1, n.j}, {n.i, n.j - 1}};
    for (int k = 0; k < 4; ++k) {
      if (edge(pieces[k][0], pieces[k][1], pieces[k][2]) != EdgeState::Open) continue;
      NodeId s;
      out.push_back(pieceSplit(pieces[k][0], pieces[k][1], pieces[k][2], n, s) ? s : ends[k]);
    }
    if (hasAvenues()) {
      const Vec2 p = node(n);
      int a0, a1;
      avenuesNear({p.x, p.y, p.x, p.y}, mergeRadius(), a0, a1);
      for (int a = a0; a <= a1; ++a) {
        if (!onAvenue(a, n)) continue;
        NodeId s;
        for (int dir : {1, -1})
          if (avenueStep(a, n, dir, s)) out.push_back(s);
      }
    }
    return out;
  }
  // A crossing: the grid piece it splits, and the avenue both ways.
  const int axis = n.kind - 1, l = n.j, oa = 1 - axis;
  const Vec2 p = node(n);
  const int m = lineBelow(oa, oa == 0 ? p.x : p.y);
  const NodeId e0 = axis == 0 ? NodeId{l, m} : NodeId{m, l}, e1 = axis == 0 ? NodeId{l, m + 1} : NodeId{m + 1, l};
  if (edge(oa, e0.i, e0.j) == EdgeState::Open) {
    out.push_back(e0);
    out.push_back(e1);
  }
  NodeId s;
  for (int dir : {1, -1})
    if (avenueStep(n.i, n, dir, s)) out.push_back(s);
  return out;
}

double StreetGrid::pieceHalfWidth(NodeId a, NodeId b) const {
  // Grid pieces, split or not, are exactly axis-parallel; avenue pieces never are.
  const Vec2 pa = node(a), pb = node(b);
  const bool avenue = pa.x != pb.x && pa.y != pb.y;
  return avenue ? avenueHalfWidth() : width_ / 2;
}

double StreetGrid::pieceLaneOffset(NodeId a, NodeId b) const { return (pieceHalfWidth(a, b) - sidewalkWidth() - parkingWidth()) / 2; }

// --- roundabouts, blocks ---------------------------------------------------------------------

bool StreetGrid::isRoundabout(NodeId n) const {
  if (n.kind != 0 || n.i < 1 || n.j < 1 || n.i > lines_ - 2 || n.j > lines_ - 2) return false;
  if (unitFromHash(hash64(seed_, kTagRoundabout, n.i, n.j)) >= options_.roundabout_probability) return false;
  for (const auto& c : {std::array<int, 3>{0, n.i, n.j}, {0, n.i - 1, n.j}, {1, n.i, n.j}, {1, n.i, n.j - 1}})
    if (edge(c[0], c[1], c[2]) != EdgeState::Open) return false;
  const Vec2 p = node(n);
  int a0, a1;
  avenuesNear({p.x, p.y, p.x, p.y}, roundaboutClearRadius() + avenueHalfWidth() + width_, a0, a1);
  return a0 > a1;
}

bool StreetGrid::nearRoundabout(Vec2 p, double radius) const {
  if (options_.roundabout_probability <= 0) return false;
  int i = lineBelow(0, p.x), j = lineBelow(1, p.y);
  if (linePos(0, i + 1) - p.x < p.x - linePos(0, i)) ++i;
  if (linePos(1, j + 1) - p.y < p.y - linePos(1, j)) ++j;
  return norm(p - node({i, j})) < radius && isRoundabout({i, j});
}

Box StreetGrid::block(int i, int j) const {
  const double h = width_ / 2;
  return {linePos(0, i) + h, linePos(1, j) + h, linePos(0, i + 1) - h, linePos(1, j + 1) - h};
}

bool StreetGrid::isPark(int i, int j) const {
  if (!blockInCity(i, j)) return false;
  return unitFromHash(hash64(seed_, kTagPark, i, j)) < options_.park_probability;
}

bool StreetGrid::isSquare(int i, int j) const {
  if (!blockInCity(i, j)) return false;
  const double u = unitFromHash(hash64(seed_, kTagPark, i, j));
  return u >= options_.park_probability && u < options_.park_probability + options_.square_probability;
}

void StreetGrid::blocksNear(const Box& b, int& i0, int& i1, int& j0, int& j1) const {
  // Block content reaches at most half a street beyond its lot (sidewalk furniture, parked cars).
  i0 = std::max(-1, lineBelow(0, b.x0 - width_) - 1);
  i1 = std::min(lines_ - 1, lineBelow(0, b.x1 + width_));
  j0 = std::max(-1, lineBelow(1, b.y0 - width_) - 1);
  j1 = std::min(lines_ - 1, lineBelow(1, b.y1 + width_));
}

}  // namespace urbanslam::sim
