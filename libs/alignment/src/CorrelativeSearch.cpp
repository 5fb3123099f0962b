#include "urbanslam/alignment/CorrelativeSearch.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace urbanslam::alignment {

namespace {

struct Node {
  int angle;     // index into the headings
  int ox, oy;    // lowest translation offset of the block [cells]
  double score;  // bound (level > 0) or exact score (level 0)
};

class Search {
 public:
  Search(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& points, const MotionPrior& prior, const CorrelativeWindow& w)
      : grid_(grid), prior_(prior), r_(grid.resolution()), min_score_(w.min_score) {
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
    const Eigen::Vector2d t(prior.mean().x, prior.mean().y);
    for (int a = -k; a <= k; ++a) {
      const double dphi = a * step_, phi = prior.mean().phi + dphi;
      const Eigen::Matrix2d R = Eigen::Rotation2Dd(phi).toRotationMatrix();
      std::vector<Eigen::Vector2i> cells;
      cells.reserve(points.size());
      for (const auto& p : points) cells.push_back(grid.cellOf(R * p + t));
      dphi_.push_back(dphi);
      cells_.push_back(std::move(cells));
    }
  }

  CorrelativeResult run() {
    int top = 0;
    while (top < grid_.levels() && (1 << top) < 2 * half_cells_ + 1) ++top;
    // The prior's mean is scored first: the bound to beat, and the odometry wins ties.
    const int centre = static_cast<int>(dphi_.size() / 2);
    best_ = {centre, 0, 0, score(0, centre, 0, 0)};
    // Below the caller's floor the centre is a stand-in to beat, not an answer.
    below_min_ = best_.score <= min_score_;
    if (below_min_) best_.score = min_score_;
    std::vector<Node> roots;
    const int s = 1 << top;
    for (int a = 0; a < static_cast<int>(dphi_.size()); ++a)
      for (int ox = -half_cells_; ox <= half_cells_; ox += s)
        for (int oy = -half_cells_; oy <= half_cells_; oy += s) roots.push_back({a, ox, oy, score(top, a, ox, oy)});
    branch(std::move(roots), top);
    CorrelativeResult out;
    out.pose = {prior_.mean().x + best_.ox * r_, prior_.mean().y + best_.oy * r_,
                common::wrapToPi(prior_.mean().phi + dphi_[static_cast<size_t>(best_.angle)])};
    out.score = best_.score;
    out.scan_score = best_.score - prior_.logDensity(out.pose);
    out.nodes = nodes_;
    out.below_min_score = below_min_;
    return out;
  }

 private:
  double score(int level, int a, int ox, int oy) {
    ++nodes_;
    const float* values = grid_.levelData(level);
    const int w = grid_.levelWidth(level), h = grid_.levelHeight(level), pad = grid_.pad();
    const float floor = grid_.floorValue();
    const int shift = LikelihoodGrid::shiftOf(level);
    double sum = 0;
    for (const auto& c : cells_[static_cast<size_t>(a)]) {
      const int i = c.x() + ox + pad, j = c.y() + oy + pad;
      if (i < 0 || j < 0) {
        sum += floor;
        continue;
      }
      const int ia = i >> shift, ja = j >> shift;
      sum += (ia >= w || ja >= h) ? floor : values[static_cast<size_t>(ja) * static_cast<size_t>(w) + static_cast<size_t>(ia)];
    }
    const int last = std::min(half_cells_, ox + (1 << level) - 1), last_y = std::min(half_cells_, oy + (1 << level) - 1);
    const double m2 = prior_.minMahalanobis2(ox * r_, last * r_, oy * r_, last_y * r_, dphi_[static_cast<size_t>(a)]);
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
        if (n.ox + dx <= half_cells_ && n.oy + dy <= half_cells_)
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

  const LikelihoodGrid& grid_;
  const MotionPrior& prior_;
  double r_, step_ = 0;
  double min_score_;
  int half_cells_ = 0, nodes_ = 0;
  std::vector<double> dphi_;
  std::vector<std::vector<Eigen::Vector2i>> cells_;
  Node best_{0, 0, 0, 0};
  bool below_min_ = false;
};

}  // namespace

CorrelativeResult correlativeSearch(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& points, const MotionPrior& prior,
                                    const CorrelativeWindow& window) {
  return Search(grid, points, prior, window).run();
}

}  // namespace urbanslam::alignment
