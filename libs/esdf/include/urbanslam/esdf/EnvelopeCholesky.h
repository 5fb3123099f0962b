#pragma once
// Solves the information system of a window of consecutive poses [first, last) in pose order
// with a block envelope (profile) Cholesky factorisation. Used by the partial recovery of the
// recent poses after each step: there the window is a short odometry chain with a few
// in-window loop closures, so the envelope (for each pose, the blocks back to its oldest linked
// pose in the window) is narrow and fill stays inside it. A general sparse factorisation pays
// an ordering and a symbolic analysis on every call for nothing here; this is a few 3x3 block
// products per pose. The worst case (a link from the newest to the oldest pose) is a dense
// factorisation of the window.
#include <Eigen/Core>
#include <vector>

#include "urbanslam/esdf/InformationState.h"

namespace urbanslam::esdf {

class EnvelopeCholesky {
 public:
  // Factorises Lambda restricted to poses [first, last). Throws std::runtime_error when the
  // block is not positive definite.
  void factorize(const InformationState& state, int first, int last);
  // Solves Lambda_sub x = b (b: 3 * (last - first) rows).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Stored 3x3 blocks of the factor (for statistics and tests).
  size_t storedBlocks() const { return blocks_.size(); }

 private:
  int n_ = 0;
  std::vector<int> lo_;       // lo_[p]: first column of row p's envelope (window indices)
  std::vector<size_t> row_;   // row_[p]: index in blocks_ of L(p, lo_[p])
  std::vector<Mat3> blocks_;  // L(p, lo_[p] .. p), row after row
  std::vector<Mat3> inv_;     // L(p, p)^-1
  const Mat3& l(int p, int j) const { return blocks_[row_[p] + static_cast<size_t>(j - lo_[p])]; }
  Mat3& l(int p, int j) { return blocks_[row_[p] + static_cast<size_t>(j - lo_[p])]; }
};

}  // namespace urbanslam::esdf
