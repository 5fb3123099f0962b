#include "urbanslam/alignment/IndexedReference.h"

namespace urbanslam::alignment {

namespace {

std::vector<Eigen::Vector2d> positions(const PointSet& s) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(s.size());
  for (const auto& q : s) out.push_back(q.p);
  return out;
}

bool sameOptions(const LineNormalOptions& a, const LineNormalOptions& b) {
  return a.line_tolerance_m == b.line_tolerance_m && a.max_gap_m == b.max_gap_m && a.max_gap_range_fraction == b.max_gap_range_fraction &&
         a.min_points == b.min_points && a.min_length_m == b.min_length_m;
}

}  // namespace

IndexedReference::IndexedReference(PointSet points) : points_(std::move(points)), index_(positions(points_)) {}

const std::vector<LineNormal>& IndexedReference::normals(const LineNormalOptions& options) const {
  for (const auto& [o, n] : normals_)
    if (sameOptions(o, options)) return n;
  normals_.emplace_back(options, computeLineNormals(points_, options));
  return normals_.back().second;
}

}  // namespace urbanslam::alignment
