#include "urbanslam/esdf/EnvelopeCholesky.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

#include "urbanslam/esdf/Recovery.h"

namespace urbanslam::esdf {

void EnvelopeCholesky::factorize(const InformationState& s, int first, int last) {
  if (first < 0 || last > s.size() || first >= last) throw std::invalid_argument("EnvelopeCholesky: bad pose range");
  n_ = last - first;
  lo_.assign(static_cast<size_t>(n_), 0);
  row_.assign(static_cast<size_t>(n_), 0);
  size_t total = 0;
  for (int p = 0; p < n_; ++p) {
    int lo = p;
    for (const auto& link : s.links(first + p))
      if (link.other >= first && link.other < first + p) lo = std::min(lo, link.other - first);
    lo_[p] = lo;
    row_[p] = total;
    total += static_cast<size_t>(p - lo + 1);
  }
  blocks_.assign(total, Mat3::Zero());
  inv_.resize(static_cast<size_t>(n_));
  // Scatter the lower triangle: L(p, j) starts as Lambda(p, j) for j <= p.
  for (int p = 0; p < n_; ++p) {
    l(p, p) = s.diagonal(first + p);
    for (const auto& link : s.links(first + p)) {
      const int j = link.other - first;
      if (j >= 0 && j < p) l(p, j) = link.block;  // Lambda(p, j)
    }
  }
  // Row-oriented block Cholesky: L(p, j) = (A(p, j) - sum_k L(p, k) L(j, k)') L(j, j)^-T over
  // the overlap of the two envelopes, then L(p, p) = chol(A(p, p) - sum_k L(p, k) L(p, k)').
  for (int p = 0; p < n_; ++p) {
    for (int j = lo_[p]; j < p; ++j) {
      Mat3 a = l(p, j);
      for (int k = std::max(lo_[p], lo_[j]); k < j; ++k) a.noalias() -= l(p, k) * l(j, k).transpose();
      l(p, j).noalias() = a * inv_[j].transpose();  // a L(j, j)^-T
    }
    Mat3 d = l(p, p);
    for (int k = lo_[p]; k < p; ++k) d.noalias() -= l(p, k) * l(p, k).transpose();
    Eigen::LLT<Mat3> llt(d);
    if (llt.info() != Eigen::Success) throw NotPositiveDefinite("information matrix is not positive definite (window)");
    l(p, p) = llt.matrixL();
    // The 3x3 triangular inverses once per pose: the block products above and the solves then
    // stay fixed-size products (a 3x3 triangular solve goes through Eigen's generic kernel).
    inv_[p] = l(p, p).triangularView<Eigen::Lower>().solve(Mat3::Identity());
  }
}

Eigen::VectorXd EnvelopeCholesky::solve(const Eigen::VectorXd& b) const {
  if (b.size() != 3 * n_) throw std::invalid_argument("EnvelopeCholesky::solve: wrong right-hand side size");
  // L y = b (rows), then L' x = y (columns of L', i.e. rows of L taken backwards).
  Eigen::VectorXd y = b;
  for (int p = 0; p < n_; ++p) {
    Vec3 r = y.segment<3>(3 * p);
    for (int k = lo_[p]; k < p; ++k) r.noalias() -= l(p, k) * y.segment<3>(3 * k);
    y.segment<3>(3 * p) = inv_[p] * r;
  }
  for (int p = n_ - 1; p >= 0; --p) {
    const Vec3 r = y.segment<3>(3 * p);
    y.segment<3>(3 * p) = inv_[p].transpose() * r;
    const Vec3 xp = y.segment<3>(3 * p);
    for (int k = lo_[p]; k < p; ++k) y.segment<3>(3 * k).noalias() -= l(p, k).transpose() * xp;
  }
  return y;
}

}  // namespace urbanslam::esdf
