#include "urbanslam/sim/StreetGrid.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Random.h"

namespace urbanslam::sim {

namespace {
// Tags keep the hash streams of different features apart.
constexpr uint64_t kTagLine = 1, kTagDeadEnd = 2, kTagDeadEndSide = 3, kTagPark = 4;
}  // namespace

StreetGrid::StreetGrid(const CityOptions& options)
    : options_(options), seed_(static_cast<uint64_t>(options.seed)), width_(options.street_width_m) {
  // Block side = pitch - width + jitter(i+1) - jitter(i): with jitter in [-J, J] and
  // J = (max - min) / 4 every block stays within [block_min_m, block_max_m].
  pitch_ = (options.block_min_m + options.block_max_m) / 2 + width_;
  jitter_ = (options.block_max_m - options.block_min_m) / 4;
  const double side = std::sqrt(options.area_km2) * 1000.0;
  lines_ = std::max(2, static_cast<int>(std::floor(side / pitch_)) + 1);
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

bool StreetGrid::deadEndCandidate(int axis, int i, int j) const {
  // Only pieces between interior intersections; the city's edge streets stay open.
  const int i1 = axis == 0 ? i + 1 : i, j1 = axis == 1 ? j + 1 : j;
  if (i <= 0 || j <= 0 || i1 >= lines_ - 1 || j1 >= lines_ - 1) return false;
  return unitFromHash(hash64(seed_, kTagDeadEnd, axis, i, j)) < options_.dead_end_probability;
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

bool StreetGrid::deadEndClosedAtEnd(int axis, int i, int j) const {
  return hash64(seed_, kTagDeadEndSide, axis, i, j) & 1;
}

std::vector<NodeId> StreetGrid::neighbours(NodeId n) const {
  std::vector<NodeId> out;
  if (edge(0, n.i, n.j) == EdgeState::Open) out.push_back({n.i + 1, n.j});
  if (edge(1, n.i, n.j) == EdgeState::Open) out.push_back({n.i, n.j + 1});
  if (edge(0, n.i - 1, n.j) == EdgeState::Open) out.push_back({n.i - 1, n.j});
  if (edge(1, n.i, n.j - 1) == EdgeState::Open) out.push_back({n.i, n.j - 1});
  return out;
}

Box StreetGrid::block(int i, int j) const {
  const double h = width_ / 2;
  return {linePos(0, i) + h, linePos(1, j) + h, linePos(0, i + 1) - h, linePos(1, j + 1) - h};
}

bool StreetGrid::isPark(int i, int j) const {
  if (i < 0 || j < 0 || i >= lines_ - 1 || j >= lines_ - 1) return false;
  return unitFromHash(hash64(seed_, kTagPark, i, j)) < options_.park_probability;
}

void StreetGrid::blocksNear(const Box& b, int& i0, int& i1, int& j0, int& j1) const {
  // Block content reaches at most half a street beyond its lot (sidewalk furniture, parked cars).
  i0 = std::max(-1, lineBelow(0, b.x0 - width_) - 1);
  i1 = std::min(lines_ - 1, lineBelow(0, b.x1 + width_));
  j0 = std::max(-1, lineBelow(1, b.y0 - width_) - 1);
  j1 = std::min(lines_ - 1, lineBelow(1, b.y1 + width_));
}

}  // namespace urbanslam::sim
