#include "urbanslam/io/GridTiles.h"

#include <mrpt/img/CImage.h>
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <tuple>
#include <utility>

#include "MrptConversions.h"
#include "OccupancyGridMrpt.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/ParallelJobs.h"

namespace urbanslam::io {

namespace {
// A block of tiles is drawn from one grid: at most this many cells a side besides its scans' rays
// (two 2000-cell tiles), which bounds the grid's memory while most scans go into one block.
constexpr int kBlockCells = 4000;
// Threads drawing blocks at once, each holding a block's grid (up to 110 MB): two halve the
// tiles' time and bound the output phase's memory whatever the machine's cores.
constexpr size_t kMaxWorkers = 2;
}  // namespace

std::vector<GridTile> writeOccupancyGridTiles(const std::string& dir, const std::vector<PosedScan>& scans, const OccupancyGridOptions& o,
                                              int tile_cells) {
  if (!(o.resolution_m > 0) || tile_cells < 1) throw common::InputError(dir + ": bad grid tile options");
  const double r = o.resolution_m;
  const int t = tile_cells;
  const double side = t * r;
  std::filesystem::create_directories(dir);

  // Which scans each block of tiles takes: those whose rays can reach it. A ray ends where MRPT's
  // insertion ends it: a return at its range (at most the insertion range), a beam without one
  // at half the last return's range (half the insertion range before the first), so the box of
  // the sensor and every ray's end, grown by a metre for the cells' rounding, holds every cell
  // the scan changes. Tiles are drawn a block of them at a time, from one grid that holds every
  // ray of the block's scans (so MRPT never grows it): a scan is inserted once per block it
  // reaches, not once per tile, and the grid reaches only as far as those rays do.
  const long block = std::max(1, kBlockCells / t);  // tiles per block side
  const auto blockOf = [block](long tile) { return tile >= 0 ? tile / block : -((-tile + block - 1) / block); };
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> boxes(scans.size());
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
      boxes[k] = {x0 - pad, y0 - pad, x1 + pad, y1 + pad};
      for (long i = blockOf(static_cast<long>(std::floor(boxes[k].x0 / side)));
           i <= blockOf(static_cast<long>(std::floor(boxes[k].x1 / side))); ++i)
        for (long j = blockOf(static_cast<long>(std::floor(boxes[k].y0 / side)));
             j <= blockOf(static_cast<long>(std::floor(boxes[k].y1 / side))); ++j)
          takes[{i, j}].push_back(k);
    }
  }

  using Job = std::pair<const std::pair<long, long>, std::vector<size_t>>;  // a block and the scans it takes
  const auto drawBlock = [&](const Job& job, mrpt::maps::COccupancyGridMap2D& grid, mrpt::img::CImage& tile, LaserScan& buffer,
                             std::vector<GridTile>& written) {
    const auto& [bij, members] = job;
    const double bx0 = bij.first * block * side, by0 = bij.second * block * side;
    const double bx1 = bx0 + block * side, by1 = by0 + block * side;
    // The block and every member's rays, 2 m more (beyond MRPT's own resizing margin of 15
    // cells), in whole cells on the tiles' lattice.
    double x0 = bx0, y0 = by0, x1 = bx1, y1 = by1;
    for (const size_t k : members) {
      x0 = std::min(x0, boxes[k].x0 - 2.0);
      y0 = std::min(y0, boxes[k].y0 - 2.0);
      x1 = std::max(x1, boxes[k].x1 + 2.0);
      y1 = std::max(y1, boxes[k].y1 + 2.0);
    }
    const auto cells = [r](double d) { return std::ceil(d / r) * r; };
    grid.setSize(static_cast<float>(bx0 - cells(bx0 - x0)), static_cast<float>(bx1 + cells(x1 - bx1)),
                 static_cast<float>(by0 - cells(by0 - y0)), static_cast<float>(by1 + cells(y1 - by1)), static_cast<float>(r));
    for (const size_t k : members) {
      const auto obs = detail::toMrptScan(scans[k].get(buffer));
      const mrpt::poses::CPose3D robot(scans[k].pose.x, scans[k].pose.y, 0, scans[k].pose.phi, 0, 0);
      grid.insertObservation(*obs, robot);
    }
    for (long ti = 0; ti < block; ++ti)
      for (long tj = 0; tj < block; ++tj) {
        const double tx0 = bx0 + ti * side, ty0 = by0 + tj * side;
        // The tile's cells as MRPT draws a grid (first row = largest y, MRPT's cell-to-grey table).
        const int cx0 = grid.x2idx(tx0 + 0.5 * r), cy0 = grid.y2idx(ty0 + 0.5 * r);
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
        g.i = static_cast<int>(bij.first * block + ti);
        g.j = static_cast<int>(bij.second * block + tj);
        char name[64];
        std::snprintf(name, sizeof name, "tile_%d_%d", g.i, g.j);
        g.png = std::string(name) + ".png";
        g.origin_x_m = tx0;
        g.origin_y_m = ty0;
        const std::string base = (std::filesystem::path(dir) / name).string();
        common::writeAtomically(base + ".png", [&](const std::string& tmp) {
          if (!tile.saveToFile(tmp)) throw common::InputError(base + ".png: cannot write");
        });
        detail::writeMapServerYaml(base + ".yaml", g.png, r, tx0, ty0, o);
        written.push_back(g);
      }
  };
  // Blocks are drawn by a few worker threads, each with its own grid and image (the scans are
  // only read; a spilled store locks its reads): the tiles are most of a city run's output time.
  // Each block's tiles are the same whichever thread draws it; the index is sorted below.
  std::vector<const Job*> jobs;
  for (const Job& job : takes) jobs.push_back(&job);
  struct Worker {
    LaserScan buffer;
    mrpt::maps::COccupancyGridMap2D grid;  // one grid for every block it draws: its cells are reused
    mrpt::img::CImage tile;
    std::vector<GridTile> drawn;
  };
  std::vector<Worker> workers(common::workerCount(jobs.size(), kMaxWorkers));
  for (Worker& w : workers) {
    detail::configureGridInsertion(w.grid);
    w.tile = mrpt::img::CImage(t, t, mrpt::img::CH_GRAY);
  }
  common::runJobs(jobs.size(), workers.size(), [&](size_t w, size_t b) {
    Worker& worker = workers[w];
    drawBlock(*jobs[b], worker.grid, worker.tile, worker.buffer, worker.drawn);
  });
  std::vector<GridTile> written;
  for (const Worker& w : workers) written.insert(written.end(), w.drawn.begin(), w.drawn.end());
  std::sort(written.begin(), written.end(), [](const GridTile& a, const GridTile& b) { return std::tie(a.i, a.j) < std::tie(b.i, b.j); });
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
