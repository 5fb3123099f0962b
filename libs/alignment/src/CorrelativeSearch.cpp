#include "urbanslam/alignment/CorrelativeSearch.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace urbanslam::alignment {

namespace {

// value(0) + ... + value(n - 1) in four running sums: one chain of dependent additions would
// wait on each before the next (the grid lookups of a search are its hottest loop).
template <typename Value>
double sum4(size_t n, const Value& value) {
  const size_t n4 = n & ~static_cast<size_t>(3);
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  for (size_t k = 0; k < n4; k += 4) {
    s0 += value(k);
    s1 += value(k + 1);
    s2 += value(k + 2);
    s3 += value(k + 3);
  }
  for (size_t k = n4; k < n; ++k) s0 += value(k);
  return (s0 + s1) + (s2 + s3);
}

struct Node {
  int angle;     // index into the headings
  int ox, oy;    // lowest translation offset of the block [cells]
  double score;  // bound (level > 0) or exact score (level 0)
};

class Search {
 public:
  Search(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& points, const MotionPrior& prior, const CorrelativeWindow& w)
      : grid_(grid), prior_(prior), r_(grid.resolution()), min_score_(w.min_score), flat_prior_(w.flat_prior) {
    if (flat_prior_) flat_log_density_ = prior.logDensity(0.0);
    // A heading step that moves a typical point by one cell (Hess et al. 2016, eq. 7 takes the
    // farthest), "typical" being the median range: half the points then move by at most a cell
    // between neighbouring headings, the rest by a few, which the refinement absorbs. Outdoors
    // the farthest returns would make the step, and the search, several times finer for nothing
    // (measured on the raw benchmark logs: the same relation errors within noise, the UAL
    // rawlog's search 40 % cheaper).
    std::vector<double> ranges;
    for (const auto& p : points) ranges.push_back(p.norm());
    double far = r_;
    if (!ranges.empty()) {
      const auto q = ranges.begin() + static_cast<long>(0.5 * static_cast<double>(ranges.size() - 1));
      std::nth_element(ranges.begin(), q, ranges.end());
      far = std::max(far, *q);
    }
    step_ = std::acos(std::max(-1.0, 1.0 - r_ * r_ / (2.0 * far * far)));
    const int k = static_cast<int>(std::ceil(w.half_angle_rad / step_));
    half_cells_ = std::max(0, static_cast<int>(std::ceil(w.half_width_m / r_)));
    const auto trimmed = [&](double trim_m) {
      return half_cells_ - std::clamp(static_cast<int>(std::lround(trim_m / r_)), 0, half_cells_);
    };
    lo_x_ = -trimmed(w.trim_m[0]);
    hi_x_ = trimmed(w.trim_m[1]);
    lo_y_ = -trimmed(w.trim_m[2]);
    hi_y_ = trimmed(w.trim_m[3]);
    const Eigen::Vector2d t(prior.mean().x, prior.mean().y);
    const int64_t width = grid.levelWidth(0), stride = grid.levelStride(0), pad = grid.pad();
    // Every translation searched puts a point of cell c at c + (ox, oy), lo_ <= o <= hi_: inside
    // the base array for all of them, outside every level's array for all of them (before its
    // start, or past the top level's last block), or at the edge (checked per lookup). Outdoors
    // the scan reaches past the submap's grid and most points are of the first two kinds.
    const int top_block = 1 << grid.levels();
    const int64_t reach_w = (grid.levelWidth(0) + top_block - 1) / top_block * top_block;
    const int64_t reach_h = (grid.levelHeight(0) + top_block - 1) / top_block * top_block;
    for (int a = -k; a <= k; ++a) {
      const double dphi = a * step_, phi = prior.mean().phi + dphi;
      const Eigen::Matrix2d R = Eigen::Rotation2Dd(phi).toRotationMatrix();
      Heading h;
      h.cells.reserve(points.size());
      h.linear.reserve(points.size());
      for (const auto& p : points) {
        const Eigen::Vector2i c = grid.cellOf(R * p + t);
        const int64_t x0 = c.x() + lo_x_ + pad, x1 = static_cast<int64_t>(c.x()) + hi_x_ + pad;
        const int64_t y0 = c.y() + lo_y_ + pad, y1 = static_cast<int64_t>(c.y()) + hi_y_ + pad;
        if (x1 < 0 || y1 < 0 || x0 >= reach_w || y0 >= reach_h) {
          ++h.outside;
        } else if (x0 >= 0 && y0 >= 0 && x1 < width && y1 < grid.levelHeight(0)) {
          h.cells.push_back(c);
          h.linear.push_back((c.y() + pad) * stride + c.x() + pad);
        } else {
          h.edge.push_back(c);
        }
      }
      h.prior = prior.headingTerms(dphi);
      dphi_.push_back(dphi);
      headings_.push_back(std::move(h));
    }
  }

  CorrelativeResult run() {
    int top = 0;
    while (top < grid_.levels() && (1 << top) < std::max(hi_x_ - lo_x_, hi_y_ - lo_y_) + 1) ++top;
    // The prior's mean is scored first: the bound to beat, and the odometry wins ties.
    const int centre = static_cast<int>(dphi_.size() / 2);
    best_ = {centre, 0, 0, score(0, centre, 0, 0)};
    // Below the caller's floor the centre is a stand-in to beat, not an answer.
    below_min_ = best_.score <= min_score_;
    if (below_min_) best_.score = min_score_;
    std::vector<Node> roots;
    const int s = 1 << top;
    for (int a = 0; a < static_cast<int>(dphi_.size()); ++a)
      for (int ox = lo_x_; ox <= hi_x_; ox += s)
        for (int oy = lo_y_; oy <= hi_y_; oy += s) roots.push_back({a, ox, oy, score(top, a, ox, oy)});
    branch(std::move(roots), top);
    CorrelativeResult out;
    out.pose = {prior_.mean().x + best_.ox * r_, prior_.mean().y + best_.oy * r_,
                common::wrapToPi(prior_.mean().phi + dphi_[static_cast<size_t>(best_.angle)])};
    out.score = best_.score;
    out.scan_score = best_.score - (flat_prior_ ? flat_log_density_ : prior_.logDensity(out.pose));
    out.nodes = nodes_;
    out.below_min_score = below_min_;
    return out;
  }

 private:
  double score(int level, int a, int ox, int oy) {
    ++nodes_;
    const Heading& hd = headings_[static_cast<size_t>(a)];
    const float* values = grid_.levelData(level);
    const int w = grid_.levelWidth(level), h = grid_.levelHeight(level), stride = grid_.levelStride(level), pad = grid_.pad();
    const int shift = grid_.shiftOf(level);
    const float floor = grid_.floorValue();
    double sum = static_cast<double>(hd.outside) * floor;
    // The points inside at every translation: no per-point checks, and at full resolution one
    // addition per point.
    if (shift == 0) {
      const float* base = values + static_cast<int64_t>(oy) * stride + ox;
      const int64_t* idx = hd.linear.data();
      sum += sum4(hd.linear.size(), [&](size_t k) { return base[idx[k]]; });
    } else {
      const Eigen::Vector2i* cells = hd.cells.data();
      sum += sum4(hd.cells.size(), [&](size_t k) {
        const Eigen::Vector2i& c = cells[k];
        return values[static_cast<size_t>((c.y() + oy + pad) >> shift) * static_cast<size_t>(stride) +
                      static_cast<size_t>((c.x() + ox + pad) >> shift)];
      });
    }
    for (const auto& c : hd.edge) {
      const int i = c.x() + ox + pad, j = c.y() + oy + pad;
      if (i < 0 || j < 0) {
        sum += floor;
        continue;
      }
      const int ia = i >> shift, ja = j >> shift;
      sum += (ia >= w || ja >= h) ? floor : values[static_cast<size_t>(ja) * static_cast<size_t>(stride) + static_cast<size_t>(ia)];
    }
    if (flat_prior_) return sum + flat_log_density_;
    const int last = std::min(hi_x_, ox + (1 << level) - 1), last_y = std::min(hi_y_, oy + (1 << level) - 1);
    const double m2 = prior_.minMahalanobis2(hd.prior, ox * r_, last * r_, oy * r_, last_y * r_);
    return sum + prior_.logDensity(m2);
  }

  // Blocks best first; a block is split only while its bound beats the best pose so far.
  void branch(std::vector<Node> nodes, int level) {
    std::sort(nodes.begin(), nodes.end(), [](const Node& a, const Node& b) { return a.score > b.score; });
    for (const Node& n : nodes) {
      if (n.score <= best_.score) return;  // sorted: no later block can beat the best either
      if (level == 0) {
        best_ = n;
        below_min_ = false;
        continue;
      }
      branchChildren(n, level);
    }
  }

  void branchChildren(const Node& n, int level) {
    const int s = 1 << (level - 1);
    std::array<Node, 4> children;
    int count = 0;
    for (int dx : {0, s})
      for (int dy : {0, s})
        if (n.ox + dx <= hi_x_ && n.oy + dy <= hi_y_)
          children[static_cast<size_t>(count++)] = {n.angle, n.ox + dx, n.oy + dy, score(level - 1, n.angle, n.ox + dx, n.oy + dy)};
    for (int k = 1; k < count; ++k)  // best first (insertion sort of at most four)
      for (int m = k; m > 0 && children[static_cast<size_t>(m)].score > children[static_cast<size_t>(m - 1)].score; --m)
        std::swap(children[static_cast<size_t>(m)], children[static_cast<size_t>(m - 1)]);
    for (int k = 0; k < count; ++k) {
      const Node& c = children[static_cast<size_t>(k)];
      if (c.score <= best_.score) return;
      if (level - 1 == 0) {
        best_ = c;
        below_min_ = false;
      } else
        branchChildren(c, level - 1);
    }
  }

  // The scan's cells at one heading with the prior's mean as the translation: those inside the
  // grid at every translation searched (and their linear indices in the full-resolution levels),
  // those at its edge, and how many fall outside at every translation (the floor each).
  struct Heading {
    std::vector<Eigen::Vector2i> cells, edge;
    std::vector<int64_t> linear;
    size_t outside = 0;
    MotionPrior::HeadingTerms prior;  // the prior's bound's terms at this heading
  };
  const LikelihoodGrid& grid_;
  const MotionPrior& prior_;
  double r_, step_ = 0;
  double min_score_;
  bool flat_prior_ = false;
  double flat_log_density_ = 0;
  int half_cells_ = 0, nodes_ = 0;
  int lo_x_ = 0, hi_x_ = 0, lo_y_ = 0, hi_y_ = 0;  // the translations searched [cells]
  std::vector<double> dphi_;
  std::vector<Heading> headings_;
  Node best_{0, 0, 0, 0};
  bool below_min_ = false;
};

}  // namespace

CorrelativeResult correlativeSearch(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& points, const MotionPrior& prior,
                                    const CorrelativeWindow& window) {
  return Search(grid, points, prior, window).run();
}

}  // namespace urbanslam::alignment
