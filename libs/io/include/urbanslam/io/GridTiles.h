#pragma once
// The occupancy grid of a map too large for one image, written as square tiles at full
// resolution, one at a time: memory is bounded by one tile and its surroundings whatever the
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

struct GridTileOptions {
  double resolution_m = 0.05;
  int tile_cells = 2000;  // a tile's side in cells (100 m at 5 cm)
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
};

// A grid cell reaches this far from the sensor (MRPT's maxDistanceInsertion as the single
// grid is written with).
constexpr double kGridInsertionRangeM = 80.0;

struct GridTile {
  int i = 0, j = 0;  // lattice index
  std::string png;   // file name, relative to the folder
  double origin_x_m = 0, origin_y_m = 0;
};

// Writes the tiles into `dir` (created if needed) and `dir/tiles.csv`; returns the tiles
// written. Each file is written atomically.
std::vector<GridTile> writeOccupancyGridTiles(const std::string& dir, const std::vector<PosedScan>& scans, const GridTileOptions& options);

}  // namespace urbanslam::io
