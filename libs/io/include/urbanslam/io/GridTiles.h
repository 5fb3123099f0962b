#pragma once
// The occupancy grid of a map too large for one image, written as square tiles at full
// resolution, a block of tiles at a time: memory is bounded by one block and its surroundings whatever the
// map's size. Each tile is a PNG + YAML pair in the ROS map_server convention (so any one of
// them loads on its own) and `tiles.csv` lists them.
//
// Tiles sit on a lattice anchored at the world origin: tile (i, j) covers
// [i, i + 1) x [j, j + 1) times tile_cells * resolution_m, so tiles of two runs in the same frame
// line up. Every cell holds what one grid over the whole map would hold there (the same MRPT
// insertion: a tile's grid takes every scan whose rays reach it). Tiles that no ray
// reaches are not written.
#include <string>
#include <vector>

#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io {

struct GridTile {
  int i = 0, j = 0;  // lattice index
  std::string png;   // file name, relative to the folder
  double origin_x_m = 0, origin_y_m = 0;
};

// Writes the tiles of `tile_cells` a side at grid.resolution_m (grid.max_cells does not apply)
// into `dir` (created if needed) and `dir/tiles.csv`; returns the tiles written. Each file is
// written atomically.
std::vector<GridTile> writeOccupancyGridTiles(const std::string& dir, const std::vector<PosedScan>& scans, const OccupancyGridOptions& grid,
                                              int tile_cells);

}  // namespace urbanslam::io
