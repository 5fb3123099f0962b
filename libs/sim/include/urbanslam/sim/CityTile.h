#pragma once
// One square tile of the city: its wall segments (clipped to the tile) and a uniform grid of
// segment indices for ray casting. Built from (street grid, tile index) alone, so tiles can be
// built lazily, in any order, and dropped and rebuilt at will.
#include <cstdint>
#include <vector>

#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

struct CityTile {
  int tx = 0, ty = 0;
  Box box;
  int cells = 0;  // cells per side
  double cell_m = 0;
  std::vector<Segment> segments;
  // Compressed rows: the segments of cell (cx, cy) are index[offset[c] .. offset[c+1]),
  // c = cy * cells + cx.
  std::vector<uint32_t> offset, index;

  static CityTile build(const StreetGrid& grid, int tx, int ty, double tile_m, int cells);
};

}  // namespace urbanslam::sim
