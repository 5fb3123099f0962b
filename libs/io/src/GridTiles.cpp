#include "urbanslam/io/GridTiles.h"

#include <mrpt/img/CImage.h>
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <utility>

#include "MrptConversions.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

std::vector<GridTile> writeOccupancyGridTiles(const std::string& dir, const std::vector<PosedScan>& scans, const GridTileOptions& o) {
  if (!(o.resolution_m > 0) || o.tile_cells < 1) throw common::InputError(dir + ": bad grid tile options");
  const double r = o.resolution_m;
  const int t = o.tile_cells;
  const double side = t * r;
  std::filesystem::create_directories(dir);

  // Which scans each tile takes: those whose sensor is within reach of it. The reach covers
  // the sensor's offset on the vehicle, so the grid of a tile (the tile grown by twice the
  // reach) holds every ray of those scans without MRPT growing it.
  std::map<std::pair<long, long>, std::vector<size_t>> takes;
  const double reach = kGridInsertionRangeM;
  {
    LaserScan buffer;
    for (size_t k = 0; k < scans.size(); ++k) {
      const LaserScan& s = scans[k].get(buffer);
      if (s.ranges.empty()) continue;
      const common::Pose2 sensor = common::compose(scans[k].pose, s.sensor_pose);
      if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || std::fabs(sensor.x) > 1e7 || std::fabs(sensor.y) > 1e7)
        throw common::InputError(dir + ": a keyframe pose is beyond 10^7 m");
      for (long i = static_cast<long>(std::floor((sensor.x - reach) / side)); i <= static_cast<long>(std::floor((sensor.x + reach) / side)); ++i)
        for (long j = static_cast<long>(std::floor((sensor.y - reach) / side)); j <= static_cast<long>(std::floor((sensor.y + reach) / side));
             ++j)
          takes[{i, j}].push_back(k);
    }
  }
  // The tile's grid, in whole cells on the same lattice as the tile (2 m beyond MRPT's own
  // resizing margin of 15 cells).
  const double margin = std::ceil((2 * reach + 2.0) / r) * r;

  std::vector<GridTile> written;
  LaserScan buffer;
  for (const auto& [ij, members] : takes) {
    const double x0 = ij.first * side, y0 = ij.second * side;
    mrpt::maps::COccupancyGridMap2D grid(static_cast<float>(x0 - margin), static_cast<float>(x0 + side + margin),
                                         static_cast<float>(y0 - margin), static_cast<float>(y0 + side + margin), static_cast<float>(r));
    grid.insertionOptions.maxDistanceInsertion = static_cast<float>(kGridInsertionRangeM);
    grid.insertionOptions.wideningBeamsWithDistance = false;
    for (const size_t k : members) {
      const auto obs = detail::toMrptScan(scans[k].get(buffer));
      const mrpt::poses::CPose3D robot(scans[k].pose.x, scans[k].pose.y, 0, scans[k].pose.phi, 0, 0);
      grid.insertObservation(*obs, robot);
    }
    // The tile's cells as MRPT draws a grid (first row = largest y, MRPT's cell-to-grey table).
    const int cx0 = grid.x2idx(x0 + 0.5 * r), cy0 = grid.y2idx(y0 + 0.5 * r);
    mrpt::img::CImage tile(t, t, mrpt::img::CH_GRAY);
    bool known = false;
    for (int row = 0; row < t; ++row) {
      const auto* cells = grid.getRow(cy0 + t - 1 - row) + cx0;
      auto* pixels = tile(0, row);
      for (int c = 0; c < t; ++c) {
        known = known || cells[c] != 0;  // log-odds 0: never observed
        pixels[c] = mrpt::maps::COccupancyGridMap2D::l2p_255(cells[c]);
      }
    }
    if (!known) continue;
    GridTile g;
    g.i = static_cast<int>(ij.first);
    g.j = static_cast<int>(ij.second);
    char name[64];
    std::snprintf(name, sizeof name, "tile_%d_%d", g.i, g.j);
    g.png = std::string(name) + ".png";
    g.origin_x_m = x0;
    g.origin_y_m = y0;
    const std::string base = (std::filesystem::path(dir) / name).string();
    common::writeAtomically(base + ".png", [&](const std::string& tmp) {
      if (!tile.saveToFile(tmp)) throw common::InputError(base + ".png: cannot write");
    });
    common::AtomicFile yaml(base + ".yaml");
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "image: %s\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\noccupied_thresh: %.3f\nfree_thresh: %.3f\n",
                  g.png.c_str(), r, x0, y0, o.occupied_thresh, o.free_thresh);
    yaml.stream() << buf;
    yaml.commit();
    written.push_back(g);
  }
  common::AtomicFile index((std::filesystem::path(dir) / "tiles.csv").string());
  index.stream() << "i,j,png,origin_x_m,origin_y_m,width_cells,height_cells,resolution_m\n";
  char line[256];
  for (const GridTile& g : written) {
    std::snprintf(line, sizeof line, "%d,%d,%s,%.6f,%.6f,%d,%d,%.6f\n", g.i, g.j, g.png.c_str(), g.origin_x_m, g.origin_y_m, t, t, r);
    index.stream() << line;
  }
  index.commit();
  return written;
}

}  // namespace urbanslam::io
