#include "urbanslam/alignment/NearestNeighbours.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>

#include <nanoflann.hpp>

namespace urbanslam::alignment {

namespace {
struct Cloud {
  std::vector<Eigen::Vector2d> pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 2, uint32_t>;
}  // namespace

// The points bucketed by square cell (counting sort into one array): a bounded search looks at
// the query's cell, then ring after ring of cells around it, and stops once no farther ring can
// hold a nearer point. A matcher's queries mostly have a neighbour within centimetres (their
// gate is 0.3 m), so one or two rings answer them, in a fraction of the kd-tree's time (which
// was a third of a localization's and a tenth of a mapping run's: the refinements ask once per
// scan point and iteration). A scan's returns reach tens of metres, sparsely: the grid covers a
// square around the points' median, at most max(16 n, 65536) cells, and answers the queries
// whose bound cannot reach a point outside it: every query when no point was left out, else
// those far enough inside; the rest go to the kd-tree.
struct CellGrid {
  static constexpr double kCellM = 0.1;
  // Bounds reaching farther go to the kd-tree. 0.4 m takes ICP's gate after 0.52 m (0.31 m, the
  // shrinking schedule from 4 m by 0.6) to the grid as well; taking 0.52 m too cost more in
  // rings searched for points with no neighbour than it saved in the tree.
  static constexpr int kMaxRings = 5;
  static constexpr double kMarginM = kCellM * (kMaxRings - 1);  // the farthest bound the grid answers
  double x0 = 0, y0 = 0;
  int nx = 0, ny = 0;
  std::vector<uint32_t> start;          // per cell, into `order`; nx * ny + 1 entries
  std::vector<uint32_t> order;          // point indices, by cell
  std::vector<Eigen::Vector2d> sorted;  // the points in that order
  bool built = false;
  bool holds_all = false;  // no point was clipped: the grid answers any query, however far

  void build(const std::vector<Eigen::Vector2d>& pts) {
    const size_t n = pts.size();
    const double max_cells = std::max(16.0 * static_cast<double>(n), 65536.0);
    // The points' extent, clipped to a square of max_cells around their median.
    std::vector<double> xs(n), ys(n);
    for (size_t i = 0; i < n; ++i) xs[i] = pts[i].x(), ys[i] = pts[i].y();
    std::nth_element(xs.begin(), xs.begin() + static_cast<long>(n / 2), xs.end());
    std::nth_element(ys.begin(), ys.begin() + static_cast<long>(n / 2), ys.end());
    const double half = 0.5 * kCellM * std::floor(std::sqrt(max_cells));
    Eigen::Vector2d lo(xs[n / 2] + half, ys[n / 2] + half), hi(xs[n / 2] - half, ys[n / 2] - half);
    for (const auto& p : pts) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    lo = lo.cwiseMax(Eigen::Vector2d(xs[n / 2] - half, ys[n / 2] - half));
    hi = hi.cwiseMin(Eigen::Vector2d(xs[n / 2] + half, ys[n / 2] + half));
    if (!(lo.x() <= hi.x() && lo.y() <= hi.y())) return;
    x0 = lo.x(), y0 = lo.y();
    nx = static_cast<int>(std::floor((hi.x() - lo.x()) / kCellM)) + 1;
    ny = static_cast<int>(std::floor((hi.y() - lo.y()) / kCellM)) + 1;
    start.assign(static_cast<size_t>(nx) * static_cast<size_t>(ny) + 1, 0);
    constexpr uint32_t kOutside = std::numeric_limits<uint32_t>::max();
    std::vector<uint32_t> cell(n, kOutside);
    size_t inside = 0;
    for (size_t i = 0; i < n; ++i) {
      const double fx = (pts[i].x() - x0) / kCellM, fy = (pts[i].y() - y0) / kCellM;
      if (!(fx >= 0 && fy >= 0 && fx < nx && fy < ny)) continue;
      cell[i] = static_cast<uint32_t>(static_cast<int>(fy) * nx + static_cast<int>(fx));
      ++start[cell[i] + 1];
      ++inside;
    }
    for (size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    order.resize(inside);
    sorted.resize(inside);
    std::vector<uint32_t> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i) {
      if (cell[i] == kOutside) continue;
      const uint32_t k = next[cell[i]]++;
      order[k] = static_cast<uint32_t>(i);
      sorted[k] = pts[i];
    }
    built = true;
    holds_all = inside == n;
  }

  // Whether every point within kMarginM of q is in the grid (all are, or q is far enough inside).
  bool covers(const Eigen::Vector2d& q) const {
    return built && (holds_all || (q.x() >= x0 + kMarginM && q.y() >= y0 + kMarginM && q.x() <= x0 + kCellM * nx - kMarginM &&
                                   q.y() <= y0 + kCellM * ny - kMarginM));
  }

  // The nearest point within max_d2 (inclusive); ties to the lower index. False: none. With
  // `second_d2`, also the squared distance of the next nearest point within max_d2 (max_d2 when
  // there is none): the search then prunes by that one instead of the nearest.
  bool nearestWithin(const Eigen::Vector2d& q, double max_d2, int* index, double* distance_sq, double* second_d2 = nullptr) const {
    // A query farther than the bound from the grid's rectangle has nothing within it.
    const double ox = std::max(0.0, std::max(x0 - q.x(), q.x() - (x0 + kCellM * nx)));
    const double oy = std::max(0.0, std::max(y0 - q.y(), q.y() - (y0 + kCellM * ny)));
    if (second_d2) *second_d2 = max_d2;
    if (ox * ox + oy * oy > max_d2) return false;
    const double fx = (q.x() - x0) / kCellM, fy = (q.y() - y0) / kCellM;
    const double cxf = std::floor(fx), cyf = std::floor(fy);
    // Beyond ring k every point is farther than k cells plus q's distance to its own cell's edge.
    const double edge = kCellM * std::min(std::min(fx - cxf, 1.0 - (fx - cxf)), std::min(fy - cyf, 1.0 - (fy - cyf)));
    const long cx = static_cast<long>(cxf), cy = static_cast<long>(cyf);
    double best = max_d2, second = max_d2;
    long best_i = -1;
    double& prune = second_d2 ? second : best;  // nothing farther than this can change the answer
    for (int ring = 0; ring <= kMaxRings; ++ring) {
      const double reach = kCellM * (ring - 1) + edge;  // the nearest any point of this ring can be
      if (ring > 0 && reach > 0 && reach * reach > prune) break;
      for (long y = cy - ring; y <= cy + ring; ++y) {
        if (y < 0 || y >= ny) continue;
        const bool edge_row = y == cy - ring || y == cy + ring;
        for (long x = cx - ring; x <= cx + ring; x += (edge_row || ring == 0) ? 1 : 2 * ring) {
          if (x < 0 || x >= nx) continue;
          // The cell's nearest corner or side: farther than the best so far, nothing in it wins.
          const double gx = std::max(0.0, std::max(static_cast<double>(x) - fx, fx - static_cast<double>(x + 1)));
          const double gy = std::max(0.0, std::max(static_cast<double>(y) - fy, fy - static_cast<double>(y + 1)));
          if (kCellM * kCellM * (gx * gx + gy * gy) > prune) continue;
          const size_t c = static_cast<size_t>(y * nx + x);
          for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
            const double d2 = (sorted[k] - q).squaredNorm();
            if (d2 < best || (d2 == best && (best_i < 0 || order[k] < best_i))) {
              if (best_i >= 0) second = std::min(second, best);
              best = d2, best_i = order[k];
            } else if (d2 < second) {
              second = d2;
            }
          }
        }
      }
    }
    if (second_d2) *second_d2 = second;
    if (best_i < 0) return false;
    *index = static_cast<int>(best_i);
    *distance_sq = best;
    return true;
  }
};

// The kd-tree is built on its first query: the matchers' bounded queries all go to the grid,
// and building a tree nobody asks was a twentieth of a localization's time. Built once, under a
// once_flag: a reference may be read by several threads.
struct NearestNeighbours::Impl {
  Cloud cloud;
  CellGrid grid;
  const Tree& tree() const {
    std::call_once(tree_built, [this] { tree_ = std::make_unique<Tree>(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(8)); });
    return *tree_;
  }
  // Whether the grid answers a bounded query (else the kd-tree does): both give the same point.
  bool gridAnswers(const Eigen::Vector2d& q, double max_d2) const {
    return max_d2 <= CellGrid::kMarginM * CellGrid::kMarginM && grid.covers(q);
  }
  // The kd-tree's `n` (1 or 2) nearest within max_d2 (inclusive), nearest first: how many.
  size_t treeNearestWithin(const Eigen::Vector2d& query, double max_d2, size_t n, uint32_t* idx, double* d2) const {
    nanoflann::KNNResultSet<double, uint32_t> result(n);
    result.init(idx, d2);
    // The result set's worst distance is the search bound; the leaf test is strict, so the bound
    // is the next double above the limit to keep a point exactly at it.
    d2[n - 1] = std::nextafter(max_d2, std::numeric_limits<double>::infinity());
    const double q[2] = {query.x(), query.y()};
    tree().findNeighbors(result, q, nanoflann::SearchParams());
    return result.size();
  }

 private:
  mutable std::once_flag tree_built;
  mutable std::unique_ptr<Tree> tree_;
};

NearestNeighbours::NearestNeighbours(std::vector<Eigen::Vector2d> points) : impl_(new Impl) {
  impl_->cloud.pts = std::move(points);
  if (!impl_->cloud.pts.empty()) impl_->grid.build(impl_->cloud.pts);
}

NearestNeighbours::~NearestNeighbours() = default;

size_t NearestNeighbours::size() const { return impl_->cloud.pts.size(); }

bool NearestNeighbours::nearest(const Eigen::Vector2d& query, int* index, double* distance_sq) const {
  if (impl_->cloud.pts.empty()) return false;
  uint32_t idx = 0;
  double d2 = 0;
  const double q[2] = {query.x(), query.y()};
  if (impl_->tree().knnSearch(q, 1, &idx, &d2) == 0) return false;
  *index = static_cast<int>(idx);
  *distance_sq = d2;
  return true;
}

bool NearestNeighbours::nearestWithin(const Eigen::Vector2d& query, double max_distance_sq, int* index, double* distance_sq) const {
  if (impl_->cloud.pts.empty()) return false;
  if (impl_->gridAnswers(query, max_distance_sq)) return impl_->grid.nearestWithin(query, max_distance_sq, index, distance_sq);
  uint32_t idx = 0;
  double d2 = 0;
  if (impl_->treeNearestWithin(query, max_distance_sq, 1, &idx, &d2) == 0) return false;
  *index = static_cast<int>(idx);
  *distance_sq = d2;
  return true;
}

bool NearestNeighbours::nearestWithin(const Eigen::Vector2d& query, double max_distance_sq, Memo* memo, int* index,
                                      double* distance_sq) const {
  if (impl_->cloud.pts.empty()) return false;
  // Rounding in the distances below is far under this; a query this close to a tie searches.
  constexpr double kSlackM = 1e-9;
  const double moved = (query - memo->query).norm();  // NaN for a fresh memo: every test below fails
  if (memo->index >= 0) {
    const Eigen::Vector2d& p = impl_->cloud.pts[static_cast<size_t>(memo->index)];
    // As both searches compute it (the kd-tree's metric sums the same two squares).
    const double d2 = (p - query).squaredNorm();
    // Every other point lay at least `others` from the last query, so at least others - moved
    // from this one: farther than the memo's point, which stays the strict nearest (the answer
    // of either search, ties aside).
    if (memo->others - moved > std::sqrt(d2) + kSlackM) {
      if (d2 > max_distance_sq) return false;  // and every other point is farther still
      *index = memo->index;
      *distance_sq = d2;
      return true;
    }
  } else if (memo->others - moved > std::sqrt(max_distance_sq) + kSlackM) {
    return false;  // nothing lay within `others` of the last query
  }
  // The search, as nearestWithin's, also finding the next nearest.
  bool found = false;
  double second_d2 = max_distance_sq;
  if (impl_->gridAnswers(query, max_distance_sq)) {
    found = impl_->grid.nearestWithin(query, max_distance_sq, index, distance_sq, &second_d2);
  } else {
    uint32_t idx[2] = {0, 0};
    double d2[2] = {0, 0};
    const size_t n = impl_->treeNearestWithin(query, max_distance_sq, 2, idx, d2);
    if (n == 2 && d2[0] == d2[1]) {
      // A tie: the answer is the plain search's, whichever of the two its order finds first; the
      // memo then holds no margin.
      found = nearestWithin(query, max_distance_sq, index, distance_sq);
      second_d2 = d2[0];
    } else if (n > 0) {
      found = true;
      *index = static_cast<int>(idx[0]);
      *distance_sq = d2[0];
      if (n == 2) second_d2 = d2[1];
    }
  }
  memo->query = query;
  memo->index = found ? *index : -1;
  memo->others = std::sqrt(second_d2);
  return found;
}

size_t NearestNeighbours::knn(const Eigen::Vector2d& query, size_t k, std::vector<int>* indices, std::vector<double>* distances_sq) const {
  indices->clear();
  distances_sq->clear();
  if (impl_->cloud.pts.empty() || k == 0) return 0;
  std::vector<uint32_t> idx(k);
  distances_sq->resize(k);
  const double q[2] = {query.x(), query.y()};
  const size_t n = impl_->tree().knnSearch(q, k, idx.data(), distances_sq->data());
  distances_sq->resize(n);
  indices->assign(idx.begin(), idx.begin() + static_cast<long>(n));
  return n;
}

}  // namespace urbanslam::alignment
