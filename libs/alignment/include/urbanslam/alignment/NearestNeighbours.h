#pragma once
// Nearest-neighbour queries over a 2D point set: bounded ones (a matcher's gate) by a grid of
// cells, the rest through a nanoflann kd-tree (the one MRPT ships), built on its first use.
// nanoflann stays behind a pimpl so that only this module needs its include path.
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace urbanslam::alignment {

class NearestNeighbours {
 public:
  explicit NearestNeighbours(std::vector<Eigen::Vector2d> points);
  ~NearestNeighbours();
  NearestNeighbours(const NearestNeighbours&) = delete;
  NearestNeighbours& operator=(const NearestNeighbours&) = delete;

  size_t size() const;
  // Index of the nearest point and its squared distance; false when the set is empty.
  bool nearest(const Eigen::Vector2d& query, int* index, double* distance_sq) const;
  // The same, but only within max_distance_sq (inclusive): false when no point is that close.
  // The same answer as nearest() followed by the distance test, found faster because the search
  // prunes every branch beyond the bound (ICP's gate leaves most unmatched points far away).
  bool nearestWithin(const Eigen::Vector2d& query, double max_distance_sq, int* index, double* distance_sq) const;

  // What a bounded query found, kept for the next query of the same scan point: a refinement
  // asks again at every iteration, mostly a fraction of a millimetre from where it last asked.
  struct Memo {
    Eigen::Vector2d query = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    int index = -1;     // the nearest point within the bound (-1: none)
    double others = 0;  // every other point lies at least this far from `query`
  };
  // The same answer as nearestWithin, exactly. Where the query moved by less than half the gap
  // between the last answer and the next nearest point, that answer still holds (every other
  // point is still farther) and no search runs; else the search also finds the next nearest,
  // for the memo. `memo` starts default-constructed.
  bool nearestWithin(const Eigen::Vector2d& query, double max_distance_sq, Memo* memo, int* index, double* distance_sq) const;
  // Up to k nearest, closest first.
  size_t knn(const Eigen::Vector2d& query, size_t k, std::vector<int>* indices, std::vector<double>* distances_sq) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace urbanslam::alignment
