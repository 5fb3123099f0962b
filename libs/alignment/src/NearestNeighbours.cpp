#include "urbanslam/alignment/NearestNeighbours.h"

#include <cmath>
#include <limits>

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

struct NearestNeighbours::Impl {
  Cloud cloud;
  std::unique_ptr<Tree> tree;
};

NearestNeighbours::NearestNeighbours(std::vector<Eigen::Vector2d> points) : impl_(new Impl) {
  impl_->cloud.pts = std::move(points);
  if (!impl_->cloud.pts.empty()) impl_->tree = std::make_unique<Tree>(2, impl_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(8));
}

NearestNeighbours::~NearestNeighbours() = default;

size_t NearestNeighbours::size() const { return impl_->cloud.pts.size(); }

bool NearestNeighbours::nearest(const Eigen::Vector2d& query, int* index, double* distance_sq) const {
  if (!impl_->tree) return false;
  uint32_t idx = 0;
  double d2 = 0;
  const double q[2] = {query.x(), query.y()};
  if (impl_->tree->knnSearch(q, 1, &idx, &d2) == 0) return false;
  *index = static_cast<int>(idx);
  *distance_sq = d2;
  return true;
}

bool NearestNeighbours::nearestWithin(const Eigen::Vector2d& query, double max_distance_sq, int* index, double* distance_sq) const {
  if (!impl_->tree) return false;
  uint32_t idx = 0;
  double d2 = 0;
  nanoflann::KNNResultSet<double, uint32_t> result(1);
  result.init(&idx, &d2);
  // The result set's worst distance is the search bound; the leaf test is strict, so the bound
  // is the next double above the limit to keep a point exactly at it.
  d2 = std::nextafter(max_distance_sq, std::numeric_limits<double>::infinity());
  const double q[2] = {query.x(), query.y()};
  impl_->tree->findNeighbors(result, q, nanoflann::SearchParams());
  if (result.size() == 0) return false;
  *index = static_cast<int>(idx);
  *distance_sq = d2;
  return true;
}

size_t NearestNeighbours::knn(const Eigen::Vector2d& query, size_t k, std::vector<int>* indices, std::vector<double>* distances_sq) const {
  indices->clear();
  distances_sq->clear();
  if (!impl_->tree || k == 0) return 0;
  std::vector<uint32_t> idx(k);
  distances_sq->resize(k);
  const double q[2] = {query.x(), query.y()};
  const size_t n = impl_->tree->knnSearch(q, k, idx.data(), distances_sq->data());
  distances_sq->resize(n);
  indices->assign(idx.begin(), idx.begin() + static_cast<long>(n));
  return n;
}

}  // namespace urbanslam::alignment
