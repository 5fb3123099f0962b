#include "urbanslam/alignment/LikelihoodGrid.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace urbanslam::alignment {

namespace {
// The rows' passes below as Eigen array expressions: Eigen's SIMD packets do four or eight cells
// at once where the plain loops, which the compiler at -O2 cannot prove free of aliasing, did
// one (a max is exact either way: the same values). n may be 0 or less: nothing.
using Cells1 = Eigen::Map<Eigen::ArrayXf>;
using ConstCells1 = Eigen::Map<const Eigen::ArrayXf>;
void fillFloor(float* out, long n, float value) {
  if (n > 0) Cells1(out, n).setConstant(value);
}
}  // namespace

LikelihoodGrid::LikelihoodGrid(const PointSet& reference, const Eigen::Vector2d& centre, const LikelihoodGridOptions& o)
    : resolution_(o.resolution_m), full_levels_(std::max(0, o.full_resolution_levels)), floor_(static_cast<float>(std::log(o.miss_floor))) {
  const double reach = 3.0 * o.hit_sigma_m;  // beyond 3σ a hit adds nothing to the floor
  Eigen::Vector2d lo = centre, hi = centre;
  bool any = false;
  for (const auto& sp : reference) {
    if (std::abs(sp.p.x() - centre.x()) > o.max_radius_m || std::abs(sp.p.y() - centre.y()) > o.max_radius_m) continue;
    lo = any ? lo.cwiseMin(sp.p) : sp.p;
    hi = any ? hi.cwiseMax(sp.p) : sp.p;
    any = true;
  }
  lo.array() -= reach;
  hi.array() += reach;
  origin_ = lo;
  const int levels = std::max(0, o.levels);
  pad_ = (1 << levels) - 1;  // a block of the top level may start this many cells before cell 0
  const int w = any ? static_cast<int>(std::ceil((hi.x() - lo.x()) / resolution_)) + 1 : 1;
  const int h = any ? static_cast<int>(std::ceil((hi.y() - lo.y()) / resolution_)) + 1 : 1;
  width_ = w + pad_;
  height_ = h + pad_;
  // Rows stored in whole multiples of 64 cells: consecutive submaps' grids, a few cells apart in
  // width, then lay their rows out alike, so the cells an earlier grid wrote are mostly the ones
  // this grid writes again (reusedCells) rather than a skewed copy of them to be floored.
  stride_ = (width_ + 63) / 64 * 64;
  const int r = static_cast<int>(std::ceil(reach / resolution_));
  const double inv2s2 = 1.0 / (2.0 * o.hit_sigma_m * o.hit_sigma_m);
  // The cell value as a function of the squared distance, tabulated (a stamp of (2r+1)² cells
  // per point would otherwise cost an exp and a log each).
  constexpr int kTable = 1024;
  const double max_d2 = 2.0 * (r + 1) * (r + 1) * resolution_ * resolution_;
  std::vector<float> table(kTable + 1);
  for (int k = 0; k <= kTable; ++k)
    table[static_cast<size_t>(k)] = static_cast<float>(std::log(std::exp(-(max_d2 * k / kTable) * inv2s2) + o.miss_floor));
  // A stamped cell lies within r + 1/2 cells of its point on either axis, short of the table's
  // last entry: that entry is only ever read for a cell no stamp reached (an infinite squared
  // distance), which holds the floor, so the pass below needs no test for it.
  table[kTable] = floor_;
  const double to_index = kTable / max_d2;
  // A cell's value is the largest over the points of the table at their squared distance, and
  // the table falls with the distance: it is the table at the squared distance to the nearest
  // point. So the stamps keep that minimum (a min of doubles, cheaper than a table lookup per
  // cell), and one pass turns it into the value; a cell no stamp reached keeps the floor. The
  // minima are kept only over each row's span of stamped columns, grown as stamps reach past it:
  // a submap's grid spans every return within grid_radius_m, and filling and reading the whole
  // of it in doubles was most of the grid's cost in a city (an 80 m square of 5 cm cells).
  const size_t cells = static_cast<size_t>(stride_) * static_cast<size_t>(height_);
  const std::unique_ptr<double[]> nearest_d2(new double[cells]);  // valid within the spans only
  std::vector<int> span_lo(static_cast<size_t>(height_), 0), span_hi(static_cast<size_t>(height_), -1);
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::vector<double> dx2(static_cast<size_t>(2 * r + 1));  // a stamp's columns' squared offsets
  for (const auto& sp : reference) {
    if (std::abs(sp.p.x() - centre.x()) > o.max_radius_m || std::abs(sp.p.y() - centre.y()) > o.max_radius_m) continue;
    const Eigen::Vector2i c = cellOf(sp.p);
    // The stamp's cells inside the array, and each column's and row's squared offset once.
    const int i0 = std::max(c.x() - r, -pad_), i1 = std::min(c.x() + r, width_ - 1 - pad_);
    const int j0 = std::max(c.y() - r, -pad_), j1 = std::min(c.y() + r, height_ - 1 - pad_);
    if (i0 > i1 || j0 > j1) continue;
    for (int i = i0; i <= i1; ++i) {
      const double dx = (origin_.x() + resolution_ * (i + 0.5)) - sp.p.x();
      dx2[static_cast<size_t>(i - i0)] = dx * dx;
    }
    const int a0 = i0 + pad_, a1 = i1 + pad_;  // the stamp's columns in the array
    for (int j = j0; j <= j1; ++j) {
      const double dy = (origin_.y() + resolution_ * (j + 0.5)) - sp.p.y(), dy2 = dy * dy;
      const size_t b = static_cast<size_t>(j + pad_);
      double* row = nearest_d2.get() + b * static_cast<size_t>(stride_);
      int& lo = span_lo[b];
      int& hi = span_hi[b];
      if (lo > hi) {
        std::fill(row + a0, row + a1 + 1, kNone);
        lo = a0, hi = a1;
      } else {
        if (a0 < lo) std::fill(row + a0, row + lo, kNone), lo = a0;
        if (a1 > hi) std::fill(row + hi + 1, row + a1 + 1, kNone), hi = a1;
      }
      for (int i = a0; i <= a1; ++i) row[i] = std::min(row[i], dx2[static_cast<size_t>(i - a0)] + dy2);
    }
  }
  Ranges stale;
  Cells base = reusedCells(cells, floor_, &stale);  // the spans written below; the floor or `stale` elsewhere
  written_.emplace_back(static_cast<size_t>(height_));
  for (size_t b = 0; b < static_cast<size_t>(height_); ++b) {
    float* out = base.data() + b * static_cast<size_t>(stride_);
    const double* row = nearest_d2.get() + b * static_cast<size_t>(stride_);
    const int lo = span_lo[b], hi = span_hi[b];
    written_.back()[b] = {lo, hi};
    for (int i = lo; i <= hi; ++i) out[i] = std::max(floor_, table[static_cast<size_t>(std::min<double>(kTable, row[i] * to_index + 0.5))]);
  }
  floorStale(base, stale, written_.back(), stride_, floor_);
  level_.push_back(std::move(base));
  // Level h from level h-1 by doubling: the block of 2^h starting at (i, j) is four blocks of
  // 2^(h-1) starting at (i, j), (i+s, j), (i, j+s), (i+s, j+s).
  dims_.push_back({width_, height_, stride_});
  // Levels 1 .. full_levels_ at full resolution: the exact largest value of the block of 2^h
  // cells starting at each cell (rows first, then columns, in loops the compiler vectorises;
  // a block reaching past the edge sees the floor there). Most of a search's blocks are scored
  // at these levels, where an exact bound prunes most.
  const size_t w_ = static_cast<size_t>(stride_), h_ = static_cast<size_t>(height_);
  // Both passes write into one array: the row pass reads the level below, the column pass runs
  // in place from the first row up (row b reads rows b and b + step, and row b + step is
  // overwritten only later), so a level costs one array of memory traffic, not two. Only the
  // rows' spans are computed (a cell whose block reaches no stamp holds the floor: every value
  // is at least the floor), a tenth of the cells of a city submap's grid.
  for (int k = 1; k <= std::min(levels, full_levels_); ++k) {
    const int step = 1 << (k - 1);
    const Cells& prev = level_.back();
    Cells next = reusedCells(cells, floor_, &stale);  // the spans written below; the floor or `stale` elsewhere
    for (size_t b = 0; b < h_; ++b) {
      if (span_lo[b] > span_hi[b]) continue;
      const float* src = prev.data() + b * w_;
      float* dst = next.data() + b * w_;
      // The block starting at a reaches the span from a = lo - step on.
      const int a0 = std::max(0, span_lo[b] - step), a1 = span_hi[b], n = std::min(a1 + 1, width_ - step);
      if (n > a0) Cells1(dst + a0, n - a0) = ConstCells1(src + a0, n - a0).max(ConstCells1(src + a0 + step, n - a0));
      for (int a = std::max(a0, n); a <= a1; ++a) dst[a] = std::max(src[a], floor_);
      span_lo[b] = a0;
    }
    // The last `step` rows' blocks reach past the grid, into the floor: they stay as they are.
    for (size_t b = 0; b + static_cast<size_t>(step) < h_; ++b) {
      const size_t c = b + static_cast<size_t>(step);
      if (span_lo[c] > span_hi[c]) continue;
      float* dst = next.data() + b * w_;
      const float* r1 = next.data() + c * w_;
      // Row b's cells outside its own span hold the floor in principle (stale values in fact,
      // floored once the level is done): there the maximum is row c's value, copied.
      const int lo = span_lo[c], hi = span_hi[c];
      const int mlo = std::max(lo, span_lo[b]), mhi = std::min(hi, span_hi[b]);
      if (mlo > mhi) {
        std::copy(r1 + lo, r1 + hi + 1, dst + lo);
      } else {
        std::copy(r1 + lo, r1 + mlo, dst + lo);
        Cells1(dst + mlo, mhi - mlo + 1) = Cells1(dst + mlo, mhi - mlo + 1).max(ConstCells1(r1 + mlo, mhi - mlo + 1));
        std::copy(r1 + mhi + 1, r1 + hi + 1, dst + mhi + 1);
      }
      if (span_lo[b] > span_hi[b]) {
        span_lo[b] = span_lo[c], span_hi[b] = span_hi[c];
      } else {
        span_lo[b] = std::min(span_lo[b], span_lo[c]), span_hi[b] = std::max(span_hi[b], span_hi[c]);
      }
    }
    written_.emplace_back(static_cast<size_t>(height_));
    for (size_t b = 0; b < h_; ++b) written_.back()[b] = {span_lo[b], span_hi[b]};
    floorStale(next, stale, written_.back(), stride_, floor_);
    level_.push_back(std::move(next));
    dims_.push_back({width_, height_, stride_});
  }
  // Higher levels at 1/2^h of the resolution (Olson's multi-resolution tables): block_max holds
  // the largest value of each aligned block of 2^h cells (from the four blocks of the level
  // below), and the stored value is the largest over two blocks on each axis, which covers every
  // block of 2^h cells starting inside block I: a looser bound for a quarter of the memory.
  // The aligned blocks' maxima up to the last full-resolution level are that level's values at
  // every 2^k-th cell (the block starting there; every value is at least the floor, so the floor
  // past the edge changes no maximum): read off it instead of another pass over the base.
  const int full = std::min(levels, full_levels_);
  Cells block_max;
  int bw = width_, bh = height_, bs = stride_;  // the level below: width, height, row stride
  if (full > 0) {
    const int nw = (width_ + (1 << full) - 1) >> full, nh = (height_ + (1 << full) - 1) >> full;
    const Cells& lv = level_[static_cast<size_t>(full)];
    block_max.resize(static_cast<size_t>(nw) * static_cast<size_t>(nh));
    fillFloor(block_max.data(), static_cast<long>(block_max.size()), floor_);
    // Only the level's written spans hold more than the floor: reading every 2^k-th cell of
    // the whole grid, a cache line each, was the hottest loop of the grid.
    const RowSpans& spans = written_.back();
    for (int b = 0; b < nh; ++b) {
      const auto [lo, hi] = spans[static_cast<size_t>(b) << full];
      float* out = block_max.data() + static_cast<size_t>(b) * static_cast<size_t>(nw);
      const float* in = lv.data() + (static_cast<size_t>(b) << full) * w_;
      for (int a = (lo + (1 << full) - 1) >> full; a <= hi >> full; ++a) out[a] = in[static_cast<size_t>(a) << full];
    }
    bw = nw;
    bh = nh;
    bs = nw;
  }
  const Cells* src = full > 0 ? &block_max : &level_.front();  // the block maxima of the level below
  for (int k = full + 1; k <= levels; ++k) {
    const int nw = (bw + 1) / 2, nh = (bh + 1) / 2;
    Cells next(static_cast<size_t>(nw) * static_cast<size_t>(nh));  // every cell written below
    const auto at = [&](int a, int b) {
      return a < bw && b < bh ? (*src)[static_cast<size_t>(b) * static_cast<size_t>(bs) + static_cast<size_t>(a)] : floor_;
    };
    for (int b = 0; b < nh; ++b)
      for (int a = 0; a < nw; ++a)
        next[static_cast<size_t>(b) * static_cast<size_t>(nw) + static_cast<size_t>(a)] =
            std::max(std::max(at(2 * a, 2 * b), at(2 * a + 1, 2 * b)), std::max(at(2 * a, 2 * b + 1), at(2 * a + 1, 2 * b + 1)));
    block_max = std::move(next);
    src = &block_max;
    bw = nw;
    bh = nh;
    bs = nw;
    if (k <= full_levels_) continue;
    Cells dilated(block_max.size());  // every cell written below
    for (int b = 0; b < bh; ++b)
      for (int a = 0; a < bw; ++a)
        dilated[static_cast<size_t>(b) * static_cast<size_t>(bw) + static_cast<size_t>(a)] =
            std::max(std::max(at(a, b), at(a + 1, b)), std::max(at(a, b + 1), at(a + 1, b + 1)));
    level_.push_back(std::move(dilated));
    dims_.push_back({bw, bh, bw});
  }
}

struct LikelihoodGrid::Storage {
  struct Kept {
    Cells cells;
    float floor;
    int stride;
    RowSpans written;
  };
  // One grid's levels: local SLAM's next grid takes those of the grid before the one in use.
  static constexpr size_t kMaxKept = 3;
  std::vector<Kept> kept;
  ~Storage() { gone() = true; }
  static Storage& ofThisThread() {
    thread_local Storage storage;
    return storage;
  }
  // Set once the thread's storage is destroyed (at its exit): a grid destroyed later frees its
  // own. A plain flag, valid to the thread's end.
  static bool& gone() {
    thread_local bool flag = false;
    return flag;
  }
};

LikelihoodGrid::Cells LikelihoodGrid::reusedCells(size_t cells, float floor, Ranges* stale) {
  stale->clear();
  std::vector<Storage::Kept>& kept = Storage::ofThisThread().kept;
  size_t best = kept.size();  // the smallest kept storage large enough, of the same floor
  for (size_t k = 0; k < kept.size(); ++k)
    if (kept[k].floor == floor && kept[k].cells.size() >= cells && (best == kept.size() || kept[k].cells.size() < kept[best].cells.size()))
      best = k;
  if (best == kept.size()) {
    // Kept storage too small for this grid is freed (the submap's grid grows as a run starts):
    // only what the next grids can use stays pinned.
    kept.erase(std::remove_if(kept.begin(), kept.end(), [&](const Storage::Kept& k) { return k.floor == floor && k.cells.size() < cells; }),
               kept.end());
    Cells fresh(cells);
    fillFloor(fresh.data(), static_cast<long>(cells), floor);
    return fresh;
  }
  Storage::Kept k = std::move(kept[best]);
  kept.erase(kept.begin() + static_cast<long>(best));
  for (size_t b = 0; b < k.written.size(); ++b) {
    const auto [lo, hi] = k.written[b];
    const size_t row = b * static_cast<size_t>(k.stride);
    if (lo <= hi) stale->push_back({row + static_cast<size_t>(lo), row + static_cast<size_t>(hi) + 1});
  }
  return std::move(k.cells);
}

void LikelihoodGrid::floorStale(Cells& c, const Ranges& stale, const RowSpans& written, int stride, float floor) {
  const size_t w = static_cast<size_t>(stride);
  for (auto [s, e] : stale) {
    // A stale range is one row of the earlier grid, whose rows may be longer or shorter than
    // this grid's: cut it at this grid's rows (or past its last), each part floored outside that
    // row's span.
    while (s < e) {
      const size_t b = s / w, row = b * w, end = std::min(e, row + w);
      if (b < written.size() && written[b].first <= written[b].second) {
        const size_t lo = row + static_cast<size_t>(written[b].first), hi = row + static_cast<size_t>(written[b].second) + 1;
        if (s < lo) fillFloor(c.data() + s, static_cast<long>(std::min(end, lo) - s), floor);
        if (end > hi) fillFloor(c.data() + std::max(s, hi), static_cast<long>(end - std::max(s, hi)), floor);
      } else {
        fillFloor(c.data() + s, static_cast<long>(end - s), floor);
      }
      s = end;
    }
  }
}

LikelihoodGrid::~LikelihoodGrid() {
  if (Storage::gone()) return;
  std::vector<Storage::Kept>& kept = Storage::ofThisThread().kept;
  // A full pool keeps what it holds (storage too small for a later grid is freed when that grid
  // asks, reusedCells); this grid's levels are then freed.
  for (size_t k = 0; k < written_.size() && k < level_.size() && kept.size() < Storage::kMaxKept; ++k)
    kept.push_back({std::move(level_[k]), floor_, stride_, std::move(written_[k])});
}

}  // namespace urbanslam::alignment
