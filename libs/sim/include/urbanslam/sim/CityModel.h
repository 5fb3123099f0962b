#pragma once
// The simulated city as the sensors see it: static walls queried by box or by ray. Tiles are
// built on demand and kept in a least-recently-used cache of bounded size, so memory does not
// grow with the city's area or the length of the drive. Not thread-safe (the cache mutates on
// const queries).
#include <cstdint>
#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include "urbanslam/sim/CityOptions.h"
#include "urbanslam/sim/CityTile.h"
#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

// The first wall along a ray: its distance, the segment (with its look) and the texture
// coordinate of the hit point along it.
struct RayHit {
  double range = kNoHit;
  Segment segment;
  double u_m = 0;
};

// What a camera looks at: anything that answers rays with walls (the city, or a few known walls
// in a test).
class WallRayCaster {
 public:
  virtual ~WallRayCaster() = default;
  // The first wall along the ray (unit dir) within max_range; false: none.
  virtual bool raycast(Vec2 origin, Vec2 dir, double max_range, RayHit& hit) const = 0;
};

class CityModel : public WallRayCaster {
 public:
  explicit CityModel(const CityOptions& options);

  const StreetGrid& streets() const { return grid_; }
  double tileSize() const { return tile_m_; }
  int tileOf(double v) const;

  // The tile, from the cache or built now. The pointer stays valid while held.
  std::shared_ptr<const CityTile> tile(int tx, int ty) const;

  // All wall segments (clipped to tiles) of the tiles overlapping the box.
  std::vector<Segment> segmentsNear(const Box& box) const;
  // Distance along the ray (unit dir) to the first wall, or kNoHit within max_range. Visits only
  // the grid cells, and so the tiles, the ray crosses.
  double raycast(Vec2 origin, Vec2 dir, double max_range) const;
  // The same walk, telling which wall was hit (false: none within max_range).
  bool raycast(Vec2 origin, Vec2 dir, double max_range, RayHit& hit) const override;

  size_t tilesBuilt() const { return built_; }
  size_t tilesCached() const { return lru_.size(); }

 private:
  StreetGrid grid_;
  double tile_m_;
  int cells_;
  size_t capacity_;
  using Entry = std::pair<int64_t, std::shared_ptr<const CityTile>>;
  mutable std::list<Entry> lru_;  // most recently used first
  mutable std::unordered_map<int64_t, std::list<Entry>::iterator> index_;
  mutable size_t built_ = 0;
};

}  // namespace urbanslam::sim
