#include "urbanslam/io/GridTiles.h"

#include <mrpt/img/CImage.h>
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <utility>

#include "MrptConversions.h"
#include "OccupancyGridMrpt.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

std::vector<GridTile> writeOccupancyGridTiles(const std::string& dir, const std::vector<PosedScan>& scans, const OccupancyGridOptions& o,
                                              int tile_cells) {
  if (!(o.resolution_m > 0) || tile_cells < 1) throw common::InputError(dir + ": bad grid tile options");
  const double r = o.resolution_m;
  const int t = tile_cells;
  const double side = t * r;
  std::filesystem::create_directories(dir);

  // Which scans each tile takes: those whose rays can reach it. A ray ends where MRPT's
  // insertion ends it: a return at its range (at most the insertion range), a beam without one
  // at half the last return's range (half the insertion range before the first), so the box of
  // the sensor and every ray's end, grown by a metre for the cells' rounding, holds every cell
  // the scan changes. Bounded by the insertion range, so a tile's grid (the tile grown by twice that
  // range) holds every ray of the scans it takes without MRPT growing it.
  std::map<std::pair<long, long>, std::vector<size_t>> takes;
  const double reach = kGridInsertionRangeM;
  double widest_pad = 0;
  {
    LaserScan buffer;
    for (size_t k = 0; k < scans.size(); ++k) {
      const LaserScan& s = scans[k].get(buffer);
      if (s.ranges.empty()) continue;
      const common::Pose2 sensor = common::compose(scans[k].pose, s.sensor_pose);
      if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || std::fabs(sensor.x) > 1e7 || std::fabs(sensor.y) > 1e7)
        throw common::InputError(dir + ": a keyframe pose is beyond 10^7 m");
      // A beam without a return ends at most at half the longest return (or half the
      // insertion range), whatever the beams' order; a non-finite return reaches the range.
      double longest = reach;
      for (size_t i = 0; i < s.ranges.size(); ++i)
        if (s.valid[i]) longest = std::isfinite(s.ranges[i]) ? std::max<double>(longest, s.ranges[i]) : 2 * reach;
      const double no_return = std::min(reach, 0.5 * longest);
      double x0 = sensor.x, x1 = sensor.x, y0 = sensor.y, y1 = sensor.y;
      for (size_t i = 0; i < s.ranges.size(); ++i) {
        const double r = !s.valid[i] ? no_return : std::isfinite(s.ranges[i]) ? std::min<double>(reach, s.ranges[i]) : reach;
        const double a = sensor.phi + s.bearing(i);
        const double ex = sensor.x + r * std::cos(a), ey = sensor.y + r * std::sin(a);
        x0 = std::min(x0, ex);
        x1 = std::max(x1, ex);
        y0 = std::min(y0, ey);
        y1 = std::max(y1, ey);
      }
      // A metre for the cells' rounding, and a beam's width at the insertion range (MRPT spreads
      // the beams over the aperture its own way).
      const double pad = 1.0 + reach * std::fabs(s.angle_increment_rad);
      widest_pad = std::max(widest_pad, pad);
      for (long i = static_cast<long>(std::floor((x0 - pad) / side)); i <= static_cast<long>(std::floor((x1 + pad) / side)); ++i)
        for (long j = static_cast<long>(std::floor((y0 - pad) / side)); j <= static_cast<long>(std::floor((y1 + pad) / side)); ++j)
          takes[{i, j}].push_back(k);
    }
  }
  // The tile's grid, in whole cells on the same lattice as the tile: the sensor of a scan it takes
  // is within the reach and the pad of it, so every ray ends within twice the reach and the pad
  // (and 2 m more, beyond MRPT's own resizing margin of 15 cells).
  const double margin = std::ceil((2 * reach + widest_pad + 2.0) / r) * r;

  std::vector<GridTile> written;
  LaserScan buffer;
  for (const auto& [ij, members] : takes) {
    const double x0 = ij.first * side, y0 = ij.second * side;
    mrpt::maps::COccupancyGridMap2D grid(static_cast<float>(x0 - margin), static_cast<float>(x0 + side + margin),
                                         static_cast<float>(y0 - margin), static_cast<float>(y0 + side + margin), static_cast<float>(r));
    detail::configureGridInsertion(grid);
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
    detail::writeMapServerYaml(base + ".yaml", g.png, r, x0, y0, o);
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
