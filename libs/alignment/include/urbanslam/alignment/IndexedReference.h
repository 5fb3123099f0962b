#pragma once
// The reference side of an alignment with what every stage asks of it: its points, a kd-tree
// over them and their line normals. One alignment used to build the tree three times and the
// normals three times (ICP, covariance, constraint ratio), and the pipeline matches every scan
// between two keyframes against the same submap: built once, it serves them all.
#include <deque>
#include <utility>
#include <vector>

#include "urbanslam/alignment/LineNormals.h"
#include "urbanslam/alignment/NearestNeighbours.h"
#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

class IndexedReference {
 public:
  explicit IndexedReference(PointSet points);
  IndexedReference(const IndexedReference&) = delete;
  IndexedReference& operator=(const IndexedReference&) = delete;

  const PointSet& points() const { return points_; }
  const NearestNeighbours& index() const { return index_; }
  // One normal per point (LineNormals.h), computed on first use for each set of options (ICP and
  // the covariance may use different ones). Not thread-safe: one alignment at a time.
  const std::vector<LineNormal>& normals(const LineNormalOptions& options) const;

 private:
  PointSet points_;
  NearestNeighbours index_;
  // A deque: references handed out stay valid when normals for other options are added.
  mutable std::deque<std::pair<LineNormalOptions, std::vector<LineNormal>>> normals_;
};

}  // namespace urbanslam::alignment
