#include "urbanslam/sim/CityTile.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/BlockGenerator.h"

namespace urbanslam::sim {

CityTile CityTile::build(const StreetGrid& grid, int tx, int ty, double tile_m, int cells) {
  CityTile t;
  t.tx = tx;
  t.ty = ty;
  t.box = {tx * tile_m, ty * tile_m, (tx + 1) * tile_m, (ty + 1) * tile_m};
  t.cells = cells;
  t.cell_m = tile_m / cells;

  // Everything that may reach into the tile, generated in a fixed order and clipped to it.
  std::vector<Segment> raw;
  int i0, i1, j0, j1;
  grid.blocksNear(t.box, i0, i1, j0, j1);
  const double reach = grid.streetWidth();
  for (int i = i0; i <= i1; ++i)
    for (int j = j0; j <= j1; ++j) {
      if (!grid.blockExists(i, j)) continue;
      const Box b = grid.block(i, j);
      if (!Box{b.x0 - reach, b.y0 - reach, b.x1 + reach, b.y1 + reach}.overlaps(t.box)) continue;
      generateBlock(grid, i, j, raw);
    }
  for (int axis = 0; axis < 2; ++axis)
    for (int i = std::max(0, i0); i <= i1 + 1; ++i)
      for (int j = std::max(0, j0); j <= j1 + 1; ++j)
        if (grid.edge(axis, i, j) == EdgeState::DeadEnd) generateDeadEnd(grid, axis, i, j, raw);
  for (int i = std::max(0, i0); i <= i1 + 1; ++i)
    for (int j = std::max(0, j0); j <= j1 + 1; ++j)
      if (grid.isRoundabout({i, j})) generateRoundabout(grid, {i, j}, raw);
  for (const Segment& s : raw) {
    Segment c;
    if (clipSegment(s, t.box, c)) t.segments.push_back(c);
  }

  // Grid: each segment goes into every cell of its bounding box (walls are mostly axis-aligned
  // and short, so this is nearly exact and much simpler than walking the segment).
  auto cellRange = [&](double a, double b, double origin, int& c0, int& c1) {
    c0 = std::clamp(static_cast<int>(std::floor((std::min(a, b) - origin) / t.cell_m)), 0, cells - 1);
    c1 = std::clamp(static_cast<int>(std::floor((std::max(a, b) - origin) / t.cell_m)), 0, cells - 1);
  };
  std::vector<uint32_t> count(static_cast<size_t>(cells) * cells + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      t.offset.assign(count.size(), 0);
      for (size_t c = 0; c + 1 < count.size(); ++c) t.offset[c + 1] = t.offset[c] + count[c];
      t.index.resize(t.offset.back());
      std::fill(count.begin(), count.end(), 0);
    }
    for (uint32_t k = 0; k < t.segments.size(); ++k) {
      const Segment& s = t.segments[k];
      int x0, x1, y0, y1;
      cellRange(s.a.x, s.b.x, t.box.x0, x0, x1);
      cellRange(s.a.y, s.b.y, t.box.y0, y0, y1);
      for (int cy = y0; cy <= y1; ++cy)
        for (int cx = x0; cx <= x1; ++cx) {
          const size_t c = static_cast<size_t>(cy) * cells + cx;
          if (pass == 1) t.index[t.offset[c] + count[c]] = k;
          ++count[c];
        }
    }
  }
  return t;
}

}  // namespace urbanslam::sim
