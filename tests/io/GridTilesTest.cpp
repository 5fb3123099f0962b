// Grid tiles against one grid over the whole map: the Intel excerpt at its reference poses,
// written both ways; every tile's cells must be the whole grid's cells there.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "TestPaths.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/GridTiles.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam {
namespace {

// "origin: [x, y, 0.0]" of a map_server YAML.
std::pair<double, double> yamlOrigin(const std::filesystem::path& yaml) {
  std::ifstream in(yaml);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("origin: [", 0) == 0) {
      double x = 0, y = 0;
      std::sscanf(line.c_str(), "origin: [%lf, %lf", &x, &y);
      return {x, y};
    }
  ADD_FAILURE() << yaml << " has no origin";
  return {0, 0};
}

TEST(GridTiles, EveryTileHoldsTheWholeGridsCells) {
  std::vector<io::LaserScan> scans;
  std::vector<common::Pose2> poses;
  auto src = io::openDataSource(test::repoPath("rawlogs/intel-corrected-excerpt.log.gz"));
  io::Measurement m;
  while (src->next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) scans.push_back(*s);
    if (auto* r = std::get_if<io::ReferencePose>(&m)) poses.push_back(r->pose);
  }
  ASSERT_EQ(scans.size(), poses.size());
  std::vector<io::PosedScan> posed;
  for (size_t i = 0; i < scans.size(); i += 3) posed.push_back({poses[i], &scans[i]});

  const auto d = test::scratchDir("grid_tiles");
  io::OccupancyGridOptions whole;
  whole.resolution_m = 0.1;
  const auto [w, h] = io::writeOccupancyGrid((d / "whole").string(), posed, whole);
  const cv::Mat reference = cv::imread((d / "whole.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(reference.cols, w);
  ASSERT_EQ(reference.rows, h);
  const auto [gx, gy] = yamlOrigin(d / "whole.yaml");

  // 64 cells: 6.4 m tiles, so that the excerpt spans several.
  const auto tiles = io::writeOccupancyGridTiles((d / "tiles").string(), posed, whole, 64);
  ASSERT_GT(tiles.size(), 4u);

  // The whole grid's cells, tile by tile; an unknown cell is MRPT's grey for log-odds 0.
  const uchar unknown = reference.at<uchar>(0, 0);
  long compared = 0, differ = 0, known_in_tiles = 0;
  for (const auto& t : tiles) {
    const cv::Mat tile = cv::imread((d / "tiles" / t.png).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(tile.cols, 64);
    ASSERT_EQ(tile.rows, 64);
    const auto [ox, oy] = yamlOrigin(d / "tiles" / (t.png.substr(0, t.png.size() - 4) + ".yaml"));
    EXPECT_DOUBLE_EQ(ox, t.i * 6.4);
    EXPECT_DOUBLE_EQ(oy, t.j * 6.4);
    const long col0 = std::lround((ox - gx) / 0.1), cell_y0 = std::lround((oy - gy) / 0.1);
    for (int row = 0; row < 64; ++row)
      for (int c = 0; c < 64; ++c) {
        const long rc = col0 + c, ry = h - 1 - (cell_y0 + 63 - row);  // the same cell's row in the whole grid
        const uchar v = tile.at<uchar>(row, c);
        if (v != unknown) ++known_in_tiles;
        if (rc < 0 || rc >= w || ry < 0 || ry >= h) {
          EXPECT_EQ(v, unknown) << "tile " << t.png << " knows a cell outside the whole map";
          continue;
        }
        ++compared;
        if (reference.at<uchar>(static_cast<int>(ry), static_cast<int>(rc)) != v) ++differ;
      }
  }
  // Every known cell of the whole grid is in some tile.
  long known_whole = 0;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) known_whole += reference.at<uchar>(r, c) != unknown;
  std::printf("%zu tiles, %ld cells compared, %ld differ; known cells: whole %ld, tiles %ld\n", tiles.size(), compared, differ,
              known_whole, known_in_tiles);
  EXPECT_GT(known_whole, 10000);
  EXPECT_LE(differ, compared / 1000);  // float rounding at cell borders, two grids with other extents
  EXPECT_NEAR(static_cast<double>(known_in_tiles), static_cast<double>(known_whole), 0.001 * known_whole);

  // The index lists exactly the tiles written.
  std::ifstream index(d / "tiles" / "tiles.csv");
  std::string line;
  std::getline(index, line);
  EXPECT_EQ(line, "i,j,png,origin_x_m,origin_y_m,width_cells,height_cells,resolution_m");
  size_t rows = 0;
  while (std::getline(index, line)) ++rows;
  EXPECT_EQ(rows, tiles.size());
}

}  // namespace
}  // namespace urbanslam
