#pragma once
// What the whole occupancy grid and its tiles share: MRPT's insertion set up the same way (so a
// tile's cells are the whole grid's), and the map_server YAML beside each PNG.
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <cstdio>
#include <string>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io::detail {

inline void configureGridInsertion(mrpt::maps::COccupancyGridMap2D& grid) {
  grid.insertionOptions.maxDistanceInsertion = static_cast<float>(kGridInsertionRangeM);
  grid.insertionOptions.wideningBeamsWithDistance = false;
}

// map_server: `origin` is the pose of the lower-left pixel; the PNG's first row is the top.
inline void writeMapServerYaml(const std::string& path, const std::string& image, double resolution_m, double origin_x_m,
                               double origin_y_m, const OccupancyGridOptions& o) {
  common::AtomicFile yaml(path);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "image: %s\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\noccupied_thresh: %.3f\nfree_thresh: %.3f\n",
                image.c_str(), resolution_m, origin_x_m, origin_y_m, o.occupied_thresh, o.free_thresh);
  yaml.stream() << buf;
  yaml.commit();
}

}  // namespace urbanslam::io::detail
