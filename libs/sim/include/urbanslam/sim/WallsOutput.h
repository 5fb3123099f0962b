#pragma once
// The ground-truth map of the part of the city a drive saw: wall segments as CSV and as a PNG
// raster (white walls on black, north up), both written atomically.
#include <set>
#include <string>
#include <utility>

#include "urbanslam/sim/CityModel.h"

namespace urbanslam::sim {

struct WallsSummary {
  size_t segments = 0;
  int width_px = 0, height_px = 0;
  double resolution_m = 0;
};

// tiles: (tx, ty) indices. The raster's cell is resolution_m, coarsened so the image stays below
// max_pixels_per_side.
WallsSummary writeWalls(const CityModel& city, const std::set<std::pair<int, int>>& tiles, const std::string& csv_path,
                        const std::string& png_path, double resolution_m = 0.25, int max_pixels_per_side = 8000);

}  // namespace urbanslam::sim
