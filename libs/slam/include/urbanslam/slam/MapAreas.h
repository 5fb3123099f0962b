#pragma once
// A frozen map's scans as match references, one per square tile of the plane, built on demand
// from the keyframes near the tile and kept in a small least-recently-used cache: a vehicle
// localized in a large map only ever holds the references of the few tiles around it, never
// the whole map at once. Each tile has two: the tracking reference (the local matcher's kd-tree,
// normals, fine likelihood grid and the keyframes' free space) and a coarse likelihood grid for
// place recognition, whose search spans the whole heading circle and many tiles.
#include <cstdint>
#include <list>
#include <memory>
#include <vector>

#include "urbanslam/alignment/LikelihoodGrid.h"
#include "urbanslam/alignment/PriorScanMatcher.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/slam/KeyframeGrid.h"
#include "urbanslam/slam/Map.h"

namespace urbanslam::slam {

struct MapAreaOptions {
  double tile_m = 10.0;                     // tile side; a pose is matched against the reference of the tile it lies in
  double keyframe_reach_m = 20.0;           // a tile's reference holds the keyframes this close to the tile (their scans reach into it)
  double keyframe_spacing_m = 0.5;          // revisits thinned: one keyframe per cell this wide and heading quadrant
  size_t cached_tiles = 6;                  // tracking references kept (a few tens of MB each)
  size_t cached_coarse_tiles = 64;          // coarse grids kept (a few MB each)
  alignment::PriorMatcherOptions matcher;   // the tracking references' grid and search (grid radius set from the tile)
  alignment::LikelihoodGridOptions coarse;  // the place-recognition grids (radius set from the tile)
  alignment::ScanModelOptions scan_model;   // the keyframes' points, as local SLAM made them
};

class MapAreas {
 public:
  // `map` must outlive this and not change.
  MapAreas(const Map& map, MapAreaOptions options);

  // The tracking reference of the tile holding (x, y), in the map frame; nullptr when no
  // keyframe scan is near that tile.
  const alignment::MatchReference* reference(double x, double y);
  // The coarse likelihood grid of that tile, in the map frame; nullptr likewise.
  const alignment::LikelihoodGrid* coarseGrid(double x, double y);

  // The tile of a position (for grouping searches by tile) and its centre.
  int64_t tileKey(double x, double y) const;
  const MapAreaOptions& options() const { return options_; }
  // References built so far (cache misses), both kinds.
  size_t referencesBuilt() const { return built_fine_; }
  size_t coarseGridsBuilt() const { return built_coarse_; }

 private:
  struct Tile {
    int64_t key;
    std::unique_ptr<const alignment::MatchReference> reference;
    std::unique_ptr<const alignment::LikelihoodGrid> grid;
  };
  // The keyframes (with scans) whose references make up the tile, thinned.
  std::vector<size_t> tileKeyframes(int64_t key) const;
  Eigen::Vector2d tileCentre(int64_t key) const;
  // Their points in their own frames, as local SLAM made them, and how many in all.
  std::vector<alignment::PointSet> ownPoints(const std::vector<size_t>& keyframes, size_t* total) const;
  Tile* find(std::list<Tile>& cache, int64_t key);

  const Map& map_;
  MapAreaOptions options_;
  KeyframeGrid index_;             // the keyframes' final poses (the map's own index may predate its last recovery)
  std::list<Tile> fine_, coarse_;  // most recently used first
  size_t built_fine_ = 0, built_coarse_ = 0;
};

}  // namespace urbanslam::slam
