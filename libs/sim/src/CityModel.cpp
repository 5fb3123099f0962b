#include "urbanslam/sim/CityModel.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::sim {

namespace {
// Shifted unsigned: a left shift of a negative value is undefined behaviour.
int64_t tileKey(int tx, int ty) {
  return static_cast<int64_t>(static_cast<uint64_t>(static_cast<int64_t>(tx)) << 32) ^ static_cast<uint32_t>(ty);
}
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
}  // namespace

CityModel::CityModel(const CityOptions& options)
    : grid_(options),
      tile_m_(options.tile_size_m),
      cells_(std::max(1, static_cast<int>(std::lround(options.tile_size_m / options.cell_size_m)))),
      capacity_(static_cast<size_t>(std::max(9, options.cache_tiles))) {}

int CityModel::tileOf(double v) const { return static_cast<int>(std::floor(v / tile_m_)); }

std::shared_ptr<const CityTile> CityModel::tile(int tx, int ty) const {
  const int64_t key = tileKey(tx, ty);
  auto it = index_.find(key);
  if (it != index_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second);
    return it->second->second;
  }
  auto t = std::make_shared<const CityTile>(CityTile::build(grid_, tx, ty, tile_m_, cells_));
  ++built_;
  lru_.emplace_front(key, t);
  index_[key] = lru_.begin();
  while (lru_.size() > capacity_) {
    index_.erase(lru_.back().first);
    lru_.pop_back();
  }
  return t;
}

std::vector<Segment> CityModel::segmentsNear(const Box& box) const {
  std::vector<Segment> out;
  for (int tx = tileOf(box.x0); tx <= tileOf(box.x1); ++tx)
    for (int ty = tileOf(box.y0); ty <= tileOf(box.y1); ++ty) {
      const auto t = tile(tx, ty);
      out.insert(out.end(), t->segments.begin(), t->segments.end());
    }
  return out;
}

double CityModel::raycast(Vec2 o, Vec2 d, double max_range) const {
  RayHit hit;
  return raycast(o, d, max_range, hit) ? hit.range : kNoHit;
}

bool CityModel::raycast(Vec2 o, Vec2 d, double max_range, RayHit& hit) const {
  // Amanatides-Woo walk over the global cell grid (tiles are whole numbers of cells). A hit found
  // in a cell counts only if it lies within that cell: a long segment may be hit further on.
  const double cell = tile_m_ / cells_;
  int cx = static_cast<int>(std::floor(o.x / cell)), cy = static_cast<int>(std::floor(o.y / cell));
  const int sx = d.x > 0 ? 1 : -1, sy = d.y > 0 ? 1 : -1;
  const double inf = kNoHit;
  const double dtx = d.x != 0 ? cell / std::fabs(d.x) : inf, dty = d.y != 0 ? cell / std::fabs(d.y) : inf;
  double tx = d.x != 0 ? ((d.x > 0 ? (cx + 1) * cell : cx * cell) - o.x) / d.x : inf;
  double ty = d.y != 0 ? ((d.y > 0 ? (cy + 1) * cell : cy * cell) - o.y) / d.y : inf;
  std::shared_ptr<const CityTile> t;
  int cur_tx = 0, cur_ty = 0;
  double t_enter = 0;
  while (t_enter <= max_range) {
    const int ttx = floorDiv(cx, cells_), tty = floorDiv(cy, cells_);
    if (!t || ttx != cur_tx || tty != cur_ty) {
      t = tile(ttx, tty);
      cur_tx = ttx;
      cur_ty = tty;
    }
    const size_t c = static_cast<size_t>(cy - tty * cells_) * cells_ + (cx - ttx * cells_);
    const double t_exit = std::min(tx, ty);
    double best = inf;
    uint32_t best_k = 0;
    for (uint32_t k = t->offset[c]; k < t->offset[c + 1]; ++k) {
      const double r = raySegment(o, d, t->segments[t->index[k]]);
      if (r < best) {
        best = r;
        best_k = t->index[k];
      }
    }
    if (best <= t_exit + 1e-9) {
      if (best > max_range) return false;
      hit.range = best;
      hit.segment = t->segments[best_k];
      const Vec2 p = o + best * d;
      hit.u_m = hit.segment.u0_m + norm(p - hit.segment.a);
      return true;
    }
    if (tx < ty) {
      t_enter = tx;
      tx += dtx;
      cx += sx;
    } else {
      t_enter = ty;
      ty += dty;
      cy += sy;
    }
  }
  return false;
}

}  // namespace urbanslam::sim
