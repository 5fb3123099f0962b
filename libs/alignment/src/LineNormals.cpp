#include "urbanslam/alignment/LineNormals.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::alignment {

namespace {

// Running sums of a 2D point set: mean, scatter and the principal line in O(1) per update.
struct LineSums {
  int n = 0;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  void add(const Eigen::Vector2d& p) {
    ++n;
    sx += p.x();
    sy += p.y();
    sxx += p.x() * p.x();
    sxy += p.x() * p.y();
    syy += p.y() * p.y();
  }
  Eigen::Vector2d mean() const { return Eigen::Vector2d(sx, sy) / n; }
  Eigen::Matrix2d scatter() const {
    const Eigen::Vector2d m = mean();
    Eigen::Matrix2d C;
    C << sxx / n - m.x() * m.x(), sxy / n - m.x() * m.y(), sxy / n - m.x() * m.y(), syy / n - m.y() * m.y();
    return C;
  }
  // Normal (eigenvector of the smallest eigenvalue) and the smallest eigenvalue, in closed form
  // (Eigen's iterative solver was a tenth of a localization's time, every point of every
  // reference scan being fitted twice; its closed form for small matrices still 5 %).
  void fit(Eigen::Vector2d* normal, double* lmin) const {
    const Eigen::Matrix2d C = scatter();
    const double a = C(0, 0), b = C(0, 1), c = C(1, 1), l = smallestEigenvalue(C);
    *lmin = std::max(0.0, l);
    // (C - l I) v = 0: v is orthogonal to either row of C - l I; the longer row is the better
    // conditioned. Both rows vanish only for a multiple of the identity (no direction at all).
    const Eigen::Vector2d r0(a - l, b), r1(b, c - l);
    const Eigen::Vector2d& row = r0.squaredNorm() >= r1.squaredNorm() ? r0 : r1;
    const double len = row.norm();
    *normal = len > 0 ? Eigen::Vector2d(-row.y() / len, row.x() / len) : Eigen::Vector2d(1, 0);
  }
  // (a + c) / 2 - sqrt(((a - c) / 2)² + b²) of [[a, b], [b, c]].
  static double smallestEigenvalue(const Eigen::Matrix2d& C) {
    const double h = 0.5 * (C(0, 0) - C(1, 1));
    return 0.5 * (C(0, 0) + C(1, 1)) - std::sqrt(h * h + C(0, 1) * C(0, 1));
  }
};

bool adjacent(const ScanPoint& a, const ScanPoint& b, const LineNormalOptions& o) {
  const double d = (a.p - b.p).norm();
  if (d < o.max_gap_m) return true;
  return std::abs(a.beam - b.beam) == 1 && d < o.max_gap_range_fraction * std::max(a.range_m, b.range_m);
}

}  // namespace

std::vector<LineNormal> computeLineNormals(const PointSet& points, const LineNormalOptions& options) {
  const int n = static_cast<int>(points.size());
  std::vector<LineNormal> out(points.size());
  int piece = 0;
  for (int i = 0; i < n;) {
    LineSums s;
    s.add(points[i].p);
    int j = i + 1;
    Eigen::Vector2d normal(0, 1);
    double lmin = 0;
    for (; j < n; ++j) {
      if (!adjacent(points[j - 1], points[j], options)) break;
      if (s.n >= 2) {
        // The candidate must lie near the current line, and the line refitted with it must
        // stay thin: the first stops at corners, the second at slow bends.
        s.fit(&normal, &lmin);
        if (std::abs(normal.dot(points[j].p - s.mean())) > options.line_tolerance_m) break;
        LineSums t = s;
        t.add(points[j].p);
        if (std::sqrt(std::max(0.0, LineSums::smallestEigenvalue(t.scatter()))) > 0.5 * options.line_tolerance_m) break;
      }
      s.add(points[j].p);
    }
    // Piece [i, j).
    if (s.n >= options.min_points) {
      s.fit(&normal, &lmin);
      const double length = (points[j - 1].p - points[i].p).norm();
      if (length >= options.min_length_m) {
        for (int k = i; k < j; ++k) {
          out[k].n = normal;
          out[k].residual_var_m2 = lmin;
          out[k].piece = piece;
          out[k].valid = true;
        }
        ++piece;
      }
    }
    // A piece broken by a corner restarts at the breaking point; one that would not grow at all
    // (isolated point) moves on by one.
    i = j;
  }
  return out;
}

bool seenFromSameSide(const LineNormal& normal, const ScanPoint& ref, const Eigen::Vector2d& other_sensor, double grazing_rad) {
  if (!normal.valid || grazing_rad < 0) return true;
  const Eigen::Vector2d to_own = ref.origin - ref.p, to_other = other_sensor - ref.p;
  const double own = normal.n.dot(to_own), other = normal.n.dot(to_other);
  if ((own >= 0) == (other >= 0)) return true;
  const double s = std::sin(grazing_rad);
  return std::abs(own) <= s * to_own.norm() || std::abs(other) <= s * to_other.norm();
}

}  // namespace urbanslam::alignment
