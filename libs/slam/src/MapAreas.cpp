#include "urbanslam/slam/MapAreas.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

namespace urbanslam::slam {

namespace {

constexpr int64_t kTileBias = int64_t{1} << 30;

// Both tile coordinates in one key; positions beyond +-2^30 tiles share the border tiles.
int64_t packKey(int64_t tx, int64_t ty) {
  tx = std::clamp(tx, -kTileBias + 1, kTileBias - 1);
  ty = std::clamp(ty, -kTileBias + 1, kTileBias - 1);
  return ((tx + kTileBias) << 31) | (ty + kTileBias);
}

}  // namespace

MapAreas::MapAreas(const Map& map, MapAreaOptions options) : map_(map), options_(std::move(options)), index_(options_.tile_m / 2) {
  const double radius = options_.tile_m / 2 + options_.keyframe_reach_m;
  options_.matcher.grid.max_radius_m = radius;
  options_.coarse.max_radius_m = radius;
  for (const Keyframe& k : map_.keyframes())
    if (k.hasScan()) index_.insert(k.index, k.pose.x, k.pose.y);
}

int64_t MapAreas::tileKey(double x, double y) const {
  const auto tile = [&](double v) {
    const double t = std::floor(v / options_.tile_m);
    return static_cast<int64_t>(std::isfinite(t) ? std::clamp(t, -1e9, 1e9) : 0.0);
  };
  return packKey(tile(x), tile(y));
}

Eigen::Vector2d MapAreas::tileCentre(int64_t key) const {
  const int64_t tx = (key >> 31) - kTileBias, ty = (key & ((int64_t{1} << 31) - 1)) - kTileBias;
  return {(static_cast<double>(tx) + 0.5) * options_.tile_m, (static_cast<double>(ty) + 0.5) * options_.tile_m};
}

std::vector<size_t> MapAreas::tileKeyframes(int64_t key) const {
  const Eigen::Vector2d c = tileCentre(key);
  const double radius = options_.tile_m * M_SQRT1_2 + options_.keyframe_reach_m;
  std::vector<size_t> near;
  index_.query(c.x(), c.y(), radius, near);
  std::sort(near.begin(), near.end());
  // Revisits add scans of the same walls from the same places: the first keyframe of each cell
  // and heading quadrant stands for them (the earliest, so a rebuilt tile is the same).
  std::unordered_set<uint64_t> taken;
  std::vector<size_t> out;
  const double s = options_.keyframe_spacing_m;
  for (size_t k : near) {
    const Keyframe& kf = map_.keyframes()[k];
    if (std::hypot(kf.pose.x - c.x(), kf.pose.y - c.y()) > radius) continue;
    const auto cx = static_cast<int64_t>(std::floor(kf.pose.x / s)), cy = static_cast<int64_t>(std::floor(kf.pose.y / s));
    const auto quadrant = static_cast<int64_t>(std::floor((kf.pose.phi + M_PI) / (M_PI / 2))) & 3;
    // Unsigned: the packed cell uses the whole 64 bits, and shifting it must wrap, not overflow.
    const uint64_t cell = static_cast<uint64_t>(packKey(cx, cy)) << 2 | static_cast<uint64_t>(quadrant);
    if (s <= 0 || taken.insert(cell).second) out.push_back(k);
  }
  return out;
}

std::vector<alignment::PointSet> MapAreas::ownPoints(const std::vector<size_t>& keyframes, size_t* total) const {
  std::vector<alignment::PointSet> own;
  *total = 0;
  for (size_t k : keyframes) {
    own.push_back(alignment::pointSetFromScan(map_.scan(k), options_.scan_model, true));
    *total += own.back().size();
  }
  return own;
}

MapAreas::Tile* MapAreas::find(std::list<Tile>& cache, int64_t key) {
  for (auto it = cache.begin(); it != cache.end(); ++it)
    if (it->key == key) {
      cache.splice(cache.begin(), cache, it);
      return &cache.front();
    }
  return nullptr;
}

const alignment::MatchReference* MapAreas::reference(double x, double y) {
  const int64_t key = tileKey(x, y);
  if (Tile* t = find(fine_, key)) return t->reference.get();
  const std::vector<size_t> keyframes = tileKeyframes(key);
  size_t total = 0;
  const std::vector<alignment::PointSet> own = ownPoints(keyframes, &total);
  alignment::PointSet points;
  points.reserve(total);
  std::vector<alignment::ReferenceView> views;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    const common::Pose2& pose = map_.keyframes()[keyframes[i]].pose;
    // Each keyframe's free space in its own frame, placed by its pose (the matcher's step 2').
    views.push_back({alignment::BeamFreeSpace(own[i], options_.matcher.free_margin_m, options_.matcher.free_margin_fraction), pose});
    alignment::appendTransformed(own[i], pose, &points);
  }
  Tile tile{key, nullptr, nullptr};
  if (!points.empty())
    tile.reference = std::make_unique<const alignment::MatchReference>(std::move(points), tileCentre(key), options_.matcher, std::move(views));
  ++built_fine_;
  fine_.push_front(std::move(tile));
  while (fine_.size() > std::max<size_t>(1, options_.cached_tiles)) fine_.pop_back();
  return fine_.front().reference.get();
}

const alignment::LikelihoodGrid* MapAreas::coarseGrid(double x, double y) {
  const int64_t key = tileKey(x, y);
  if (Tile* t = find(coarse_, key)) return t->grid.get();
  const std::vector<size_t> keyframes = tileKeyframes(key);
  size_t total = 0;
  const std::vector<alignment::PointSet> own = ownPoints(keyframes, &total);
  alignment::PointSet points;
  points.reserve(total);
  for (size_t i = 0; i < keyframes.size(); ++i) alignment::appendTransformed(own[i], map_.keyframes()[keyframes[i]].pose, &points);
  Tile tile{key, nullptr, nullptr};
  if (!points.empty()) tile.grid = std::make_unique<const alignment::LikelihoodGrid>(points, tileCentre(key), options_.coarse);
  ++built_coarse_;
  coarse_.push_front(std::move(tile));
  while (coarse_.size() > std::max<size_t>(1, options_.cached_coarse_tiles)) coarse_.pop_back();
  return coarse_.front().grid.get();
}

}  // namespace urbanslam::slam
