#include "SparseInverse.h"

#include <Eigen/Core>
#include <stdexcept>

namespace urbanslam::esdf {

namespace {
using Block = Eigen::Map<const Eigen::MatrixXd>;
using MutableBlock = Eigen::Map<Eigen::MatrixXd>;
}  // namespace

std::vector<Mat3> inverseDiagonalBlocks(const SupernodalFactorView& l) {
  const int n = l.columns;
  if (n % 3 != 0) throw std::invalid_argument("inverseDiagonalBlocks: the size is not three per pose");
  std::vector<int> supernode_of(static_cast<size_t>(n));
  for (int s = 0; s < l.supernodes; ++s)
    for (int c = l.first_column[s]; c < l.first_column[s + 1]; ++c) supernode_of[static_cast<size_t>(c)] = s;
  std::vector<int> position_of(static_cast<size_t>(n), -1);  // row -> place in the supernode scattered last
  int scattered = -1;
  const auto scatter = [&](int s) {
    if (s == scattered) return;
    for (int k = l.row_begin[s]; k < l.row_begin[s + 1]; ++k) position_of[static_cast<size_t>(l.rows[k])] = k - l.row_begin[s];
    scattered = s;
  };
  std::vector<int> row_of(static_cast<size_t>(n));  // A's row -> L's row
  for (int k = 0; k < n; ++k) row_of[static_cast<size_t>(l.perm[k])] = k;

  // Z = A^-1 in L's layout. With L's supernode S (columns) over its rows S and R below:
  //   L' Z = L^-1 gives Z_RS = -Z_RR W and Z_SS = (L_SS L_SS')^-1 - W' Z_RS, W = L_RS L_SS^-1,
  // where Z_RR lies in the pattern of later supernodes (R is a clique of the filled graph).
  std::vector<double> z(static_cast<size_t>(l.value_begin[l.supernodes]));
  std::vector<Mat3> blocks(static_cast<size_t>(n / 3), Mat3::Zero());
  Eigen::MatrixXd zrr, w, zrs;
  for (int s = l.supernodes - 1; s >= 0; --s) {
    const int c0 = l.first_column[s], nc = l.first_column[s + 1] - c0;
    const int nr = l.row_begin[s + 1] - l.row_begin[s], nb = nr - nc;
    const int* rows = l.rows + l.row_begin[s];
    const Block ls(l.values + l.value_begin[s], nr, nc);
    MutableBlock zs(z.data() + l.value_begin[s], nr, nc);
    const auto lss = ls.topRows(nc).triangularView<Eigen::Lower>();
    Eigen::MatrixXd inv_lss = Eigen::MatrixXd::Identity(nc, nc);
    lss.solveInPlace(inv_lss);
    zs.topRows(nc).noalias() = inv_lss.transpose() * inv_lss;
    if (nb > 0) {
      // Gather Z_RR, column t of it from the supernode that holds row nc + t as a column.
      zrr.resize(nb, nb);
      for (int t = 0; t < nb; ++t) {
        const int c = rows[nc + t];
        const int sc = supernode_of[static_cast<size_t>(c)];
        scatter(sc);
        const int ld = l.row_begin[sc + 1] - l.row_begin[sc];
        const double* col = z.data() + l.value_begin[sc] + static_cast<long>(c - l.first_column[sc]) * ld;
        for (int u = t; u < nb; ++u) zrr(u, t) = zrr(t, u) = col[position_of[static_cast<size_t>(rows[nc + u])]];
      }
      w = ls.bottomRows(nb) * inv_lss;
      zrs.noalias() = -zrr * w;
      zs.bottomRows(nb) = zrs;
      zs.topRows(nc).noalias() -= w.transpose() * zrs;
    }
    // The diagonal blocks: entry (k1, k2) of a pose's block is stored in column min(k1, k2).
    scatter(s);
    for (int c = c0; c < c0 + nc; ++c) {
      const int a = l.perm[c], pose = a / 3;
      for (int b = 0; b < 3; ++b) {
        const int k = row_of[static_cast<size_t>(3 * pose + b)];
        if (k < c) continue;
        const double v = zs(position_of[static_cast<size_t>(k)], c - c0);
        blocks[static_cast<size_t>(pose)](a % 3, b) = blocks[static_cast<size_t>(pose)](b, a % 3) = v;
      }
    }
  }
  return blocks;
}

}  // namespace urbanslam::esdf
