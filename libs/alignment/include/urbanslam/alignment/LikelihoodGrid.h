#pragma once
// The reference scan (or submap) as a raster of per-point log-likelihoods, for correlative
// scan matching (Olson 2009, "Real-time correlative scan matching"): a cell holds
// log(exp(-d²/2σ²) + κ), d the distance from the cell's centre to the nearest reference point,
// κ the floor of a return that the reference does not explain (clutter, a moved object, a
// place seen for the first time). The score of a candidate pose is the sum over the scan's
// points of the cells they fall in, so a pose costs one lookup per point.
//
// Coarser levels for branch and bound: level h bounds, for the block of 2^h x 2^h cells whose
// lowest corner is a cell, the largest value in the block; a sum over level h bounds the score
// of every pose whose translation lies in that block (Cartographer's precomputation grids, kept
// at 1/2^h of the resolution, each value the largest over two aligned blocks per axis, as in
// Olson's multi-resolution tables: a quarter of the memory per level instead of a full copy).
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

struct LikelihoodGridOptions {
  double resolution_m = 0.05;  // cell size
  double hit_sigma_m = 0.05;   // spread of a return about the surface it hit (noise + cell size)
  double miss_floor = 0.05;    // κ: the density of an unexplained return relative to a hit's peak
  double max_radius_m = 40.0;  // cells farther than this from the centre (along x or y) are left out
  int levels = 5;              // pyramid levels above the base (blocks of 2^levels cells; wider windows get more root blocks)
  // Levels 1 .. this stored at full resolution (exact block maxima, a tighter bound), the ones
  // above at 1/2^h of it (a looser bound for a quarter of the memory and less).
  int full_resolution_levels = 2;
};

class LikelihoodGrid {
 public:
  // The reference points (in the reference's frame) around `centre`.
  LikelihoodGrid(const PointSet& reference, const Eigen::Vector2d& centre, const LikelihoodGridOptions& options);
  // The full-resolution levels' storage goes back to this thread's pool (see Storage).
  ~LikelihoodGrid();
  LikelihoodGrid(LikelihoodGrid&&) = default;
  LikelihoodGrid& operator=(LikelihoodGrid&&) = delete;
  LikelihoodGrid(const LikelihoodGrid&) = delete;
  LikelihoodGrid& operator=(const LikelihoodGrid&) = delete;

  double resolution() const { return resolution_; }
  int levels() const { return static_cast<int>(level_.size()) - 1; }
  float floorValue() const { return floor_; }
  // The cell of a point: floor((p - origin) / resolution), unbounded.
  Eigen::Vector2i cellOf(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::floor((p.x() - origin_.x()) / resolution_)),
            static_cast<int>(std::floor((p.y() - origin_.y()) / resolution_))};
  }
  // The centre of cell (i, j), where its value is taken.
  Eigen::Vector2d cellCentre(int i, int j) const { return origin_ + resolution_ * Eigen::Vector2d(i + 0.5, j + 0.5); }
  // Levels up to options' full_resolution_levels are stored at full resolution (exact block
  // maxima); higher ones at 1/2^h of it (a looser bound).
  int shiftOf(int level) const { return level <= full_levels_ ? 0 : level; }
  // Level 0: the cell's value; level h: a bound on the largest value in the block of 2^h x 2^h
  // cells whose lowest corner is (i, j). The floor outside the grid.
  float value(int level, int i, int j) const {
    const int sh = shiftOf(level);
    const Dims& d = dims_[static_cast<size_t>(level)];
    if (i + pad_ < 0 || j + pad_ < 0) return floor_;
    const int a = (i + pad_) >> sh, b = (j + pad_) >> sh;
    if (a >= d.width || b >= d.height) return floor_;
    return level_[static_cast<size_t>(level)][static_cast<size_t>(b) * static_cast<size_t>(d.stride) + static_cast<size_t>(a)];
  }
  // Raw access for tight loops: level h's values, row-major, levelWidth(h) x levelHeight(h) in
  // rows of levelStride(h) >= levelWidth(h) cells (past the width: not part of the grid); the cell
  // (i, j) of value() at ((j + pad()) >> shiftOf(h)) * levelStride(h) + ((i + pad()) >> shiftOf(h)).
  const float* levelData(int level) const { return level_[static_cast<size_t>(level)].data(); }
  int levelWidth(int level) const { return dims_[static_cast<size_t>(level)].width; }
  int levelHeight(int level) const { return dims_[static_cast<size_t>(level)].height; }
  int levelStride(int level) const { return dims_[static_cast<size_t>(level)].stride; }
  int pad() const { return pad_; }
  // The log-likelihood of one point at p (level 0).
  float score(const Eigen::Vector2d& p) const {
    const Eigen::Vector2i c = cellOf(p);
    return value(0, c.x(), c.y());
  }

 private:
  double resolution_;
  int full_levels_ = 2;
  Eigen::Vector2d origin_;  // corner of cell (0, 0)
  int pad_ = 0;             // cells before cell 0 on each axis (blocks that start outside)
  int width_ = 0, height_ = 0;
  int stride_ = 0;  // the full-resolution levels' row length in storage
  float floor_ = 0;
  struct Dims {
    int width, height, stride;
  };
  std::vector<Dims> dims_;
  // Storage whose size constructor leaves the cells unset: every level is written in full by a
  // pass over the one below, and zeroing megabytes first would double the memory traffic.
  template <typename T>
  struct NoFill : std::allocator<T> {
    template <typename U>
    struct rebind {
      using other = NoFill<U>;
    };
    NoFill() = default;
    template <typename U>
    NoFill(const NoFill<U>&) {}
    template <typename U>
    void construct(U* p) {
      ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... A>
    void construct(U* p, A&&... a) {
      ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
  };
  using Cells = std::vector<float, NoFill<float>>;
  std::vector<Cells> level_;
  // Local SLAM builds a grid of an 80 m square of 5 cm cells per keyframe, of which stamps
  // reach about a tenth: writing the floor into the rest of the base and full-resolution levels
  // was half of the grid's cost. Their storage is kept per thread when a grid is done, with the
  // span of each row the grid wrote (rows are `stride` cells); the next grid finds the floor
  // everywhere else, writes its own spans and then floors what is left of the earlier ones
  // (consecutive submaps' spans mostly overlap: resetting them first wrote most cells twice).
  using RowSpans = std::vector<std::pair<int, int>>;      // per row: first and last cell written
  using Ranges = std::vector<std::pair<size_t, size_t>>;  // [begin, end) cell indices, ascending
  struct Storage;
  // At least `cells` cells, at the floor except within `stale` (another grid's values).
  static Cells reusedCells(size_t cells, float floor, Ranges* stale);
  // Floors the cells of `stale` outside the rows' spans this grid wrote.
  static void floorStale(Cells& c, const Ranges& stale, const RowSpans& written, int stride, float floor);
  std::vector<RowSpans> written_;  // per full-resolution level (0 = base)
};

}  // namespace urbanslam::alignment
