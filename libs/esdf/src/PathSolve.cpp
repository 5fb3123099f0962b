#include "PathSolve.h"

#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>

namespace urbanslam::esdf {

namespace {
using Rows3 = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>;
using ConstRows3 = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>;
using ConstBlock = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
inline size_t at(int i) { return static_cast<size_t>(i); }
}  // namespace

PathSolution pathSolve(const SupernodalFactorView& l, const FactorIndex& index, std::vector<int>& offset_of, int pose) {
  if (pose < 0 || 3 * pose + 2 >= l.columns) throw std::out_of_range("pathSolve: no such pose in the factor");
  const auto columns = [&](int s) { return l.first_column[s + 1] - l.first_column[s]; };
  // The parent of a supernode holds the first row below its columns (every row below is an
  // ancestor's column; the minimum is taken, as a simplicial factor's rows need not be sorted).
  const auto parent = [&](int s) {
    int first = INT_MAX;
    for (int k = l.row_begin[s] + columns(s); k < l.row_begin[s + 1]; ++k) first = std::min(first, l.rows[k]);
    return first == INT_MAX ? -1 : index.supernode_of[at(first)];
  };
  PathSolution out;
  out.pose = pose;
  // The three columns' paths to the root; every row a forward solve from them writes lies there.
  for (int c = 0; c < 3; ++c)
    for (int s = index.supernode_of[at(index.row_of[at(3 * pose + c)])]; s >= 0 && offset_of[at(s)] < 0; s = parent(s)) {
      offset_of[at(s)] = 0;
      out.supernodes.push_back(s);
    }
  // A parent comes after its children in L's order: ascending is an order the solve can go in.
  std::sort(out.supernodes.begin(), out.supernodes.end());
  int rows = 0;
  out.begin.reserve(out.supernodes.size() + 1);
  for (const int s : out.supernodes) {
    out.begin.push_back(rows);
    offset_of[at(s)] = rows;
    rows += columns(s);
  }
  out.begin.push_back(rows);
  out.values.assign(3 * at(rows), 0.0);
  const auto slot = [&](int row) {
    const int s = index.supernode_of[at(row)];
    return &out.values[3 * at(offset_of[at(s)] + row - l.first_column[s])];
  };
  for (int c = 0; c < 3; ++c) slot(index.row_of[at(3 * pose + c)])[c] = 1.0;
  Eigen::Matrix<double, Eigen::Dynamic, 3> below;
  for (size_t k = 0; k < out.supernodes.size(); ++k) {
    const int s = out.supernodes[k];
    const int nc = columns(s), nr = l.row_begin[s + 1] - l.row_begin[s];
    const ConstBlock ls(l.values + l.value_begin[s], nr, nc, Eigen::OuterStride<>(nr));
    Rows3 x(&out.values[3 * at(out.begin[k])], nc, 3);
    out.work += 3.0 * static_cast<double>(nc) * (0.5 * nc + (nr - nc));
    // (A unit-diagonal LDL' factor holds D where L's diagonal would be: its columns divide by 1.)
    if (!l.unit_diagonal_ldl) ls.topRows(nc).triangularView<Eigen::Lower>().solveInPlace(x);
    if (nr == nc) continue;
    below.noalias() = ls.bottomRows(nr - nc) * x;
    const int* below_rows = l.rows + l.row_begin[s] + nc;
    for (int t = 0; t < nr - nc; ++t) {
      double* y = slot(below_rows[t]);
      y[0] -= below(t, 0);
      y[1] -= below(t, 1);
      y[2] -= below(t, 2);
    }
  }
  for (const int s : out.supernodes) offset_of[at(s)] = -1;
  // Sigma = (L^-1 P)' D^-1 (L^-1 P) for an LDL' factor: D^-1/2 goes into y (D > 0: A is
  // positive definite), so that every covariance is a plain product.
  if (l.unit_diagonal_ldl)
    for (size_t k = 0; k < out.supernodes.size(); ++k) {
      const double d = l.values[l.value_begin[out.supernodes[k]]];
      Rows3(&out.values[3 * at(out.begin[k])], 1, 3) /= std::sqrt(d);
    }
  return out;
}

Mat3 pathCovariance(const PathSolution& a, const PathSolution& b) {
  // The two paths share their upper part (up to the root): a merge of the sorted supernodes.
  Mat3 r = Mat3::Zero();
  size_t i = 0, j = 0;
  while (i < a.supernodes.size() && j < b.supernodes.size()) {
    if (a.supernodes[i] < b.supernodes[j]) {
      ++i;
    } else if (b.supernodes[j] < a.supernodes[i]) {
      ++j;
    } else {
      const int n = a.begin[i + 1] - a.begin[i];
      r.noalias() += ConstRows3(&a.values[3 * at(a.begin[i])], n, 3).transpose() * ConstRows3(&b.values[3 * at(b.begin[j])], n, 3);
      ++i;
      ++j;
    }
  }
  return r;
}

}  // namespace urbanslam::esdf
