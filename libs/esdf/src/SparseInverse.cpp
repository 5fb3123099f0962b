#include "SparseInverse.h"

#include <Eigen/Core>
#include <algorithm>
#include <stdexcept>

namespace urbanslam::esdf {

namespace {
using Block = Eigen::Map<const Eigen::MatrixXd>;
using MutableBlock = Eigen::Map<Eigen::MatrixXd>;

// When each supernode's Z can go. Z of supernode p is read only by the supernodes processed
// after it (lower ones) that have rows in its columns, its descendants in the elimination tree;
// it goes once the lowest of them is done, or after its own step when none reads it. The
// supernodes released after supernode s are supernodes[begin[s] .. begin[s + 1]).
struct ReleaseSchedule {
  std::vector<int> begin, supernodes;
};

ReleaseSchedule releaseSchedule(const SupernodalFactorView& l, const std::vector<int>& supernode_of) {
  const auto at = [](int i) { return static_cast<size_t>(i); };
  std::vector<int> last_reader(at(l.supernodes));
  for (int s = 0; s < l.supernodes; ++s) last_reader[at(s)] = s;
  for (int s = 0; s < l.supernodes; ++s)
    for (int k = l.row_begin[s] + l.first_column[s + 1] - l.first_column[s]; k < l.row_begin[s + 1]; ++k) {
      int& last = last_reader[at(supernode_of[at(l.rows[k])])];
      last = std::min(last, s);
    }
  // Bucketed by their last reader (a counting sort).
  ReleaseSchedule r{std::vector<int>(at(l.supernodes) + 1, 0), std::vector<int>(at(l.supernodes))};
  for (const int reader : last_reader) ++r.begin[at(reader) + 1];
  for (int s = 0; s < l.supernodes; ++s) r.begin[at(s) + 1] += r.begin[at(s)];
  std::vector<int> next(r.begin.begin(), r.begin.end() - 1);
  for (int s = 0; s < l.supernodes; ++s) r.supernodes[at(next[at(last_reader[at(s)])]++)] = s;
  return r;
}
}  // namespace

FactorIndex::FactorIndex(const SupernodalFactorView& l)
    : supernode_of(static_cast<size_t>(l.columns)), row_of(static_cast<size_t>(l.columns)) {
  for (int s = 0; s < l.supernodes; ++s)
    for (int c = l.first_column[s]; c < l.first_column[s + 1]; ++c) supernode_of[static_cast<size_t>(c)] = s;
  for (int k = 0; k < l.columns; ++k) row_of[static_cast<size_t>(l.perm ? l.perm[k] : k)] = k;
}

double inverseWork(const SupernodalFactorView& l) {
  double work = 0;
  for (int s = 0; s < l.supernodes; ++s) {
    const double nc = l.first_column[s + 1] - l.first_column[s], nb = l.row_begin[s + 1] - l.row_begin[s] - nc;
    work += nb * nb * nc + 2 * nb * nc * nc + nc * nc * nc / 3;
  }
  return work;
}

double factorisationWork(const SupernodalFactorView& l) {
  double work = 0;
  for (int s = 0; s < l.supernodes; ++s) {
    const double nc = l.first_column[s + 1] - l.first_column[s], nb = l.row_begin[s + 1] - l.row_begin[s] - nc;
    work += nc * nc * nc / 3 + nb * nc * nc + nb * nb * nc / 2;
  }
  return work;
}

std::vector<Mat3> inverseDiagonalBlocks(const SupernodalFactorView& l, const FactorIndex& index) {
  const int n = l.columns;
  if (n % 3 != 0) throw std::invalid_argument("inverseDiagonalBlocks: the size is not three per pose");
  const std::vector<int>& supernode_of = index.supernode_of;
  std::vector<int> position_of(static_cast<size_t>(n), -1);  // row -> place in the supernode scattered last
  int scattered = -1;
  const auto scatter = [&](int s) {
    if (s == scattered) return;
    for (int k = l.row_begin[s]; k < l.row_begin[s + 1]; ++k) position_of[static_cast<size_t>(l.rows[k])] = k - l.row_begin[s];
    scattered = s;
  };
  const std::vector<int>& row_of = index.row_of;  // A's row -> L's row

  // Z = A^-1 in L's layout. With L's supernode S (columns) over its rows S and R below:
  //   L' Z = L^-1 gives Z_RS = -Z_RR W and Z_SS = (L_SS L_SS')^-1 - W' Z_RS, W = L_RS L_SS^-1,
  // where Z_RR lies in the pattern of later supernodes (R is a clique of the filled graph).
  // Each Z is released after its last reader (releaseSchedule), so what is held at once is about
  // the Z of one path from the root, not a second factor.
  const ReleaseSchedule release_after = releaseSchedule(l, supernode_of);
  std::vector<std::vector<double>> z(static_cast<size_t>(l.supernodes));
  std::vector<Mat3> blocks(static_cast<size_t>(n / 3), Mat3::Zero());
  Eigen::MatrixXd zrr, w, zrs;
  // Z_RR of a supernode with nc columns whose rows below them are rows[nc .. nc + nb), column t
  // of it from the supernode that holds row nc + t as a column.
  const auto gather = [&](int nc, int nb, const int* rows) {
    zrr.resize(nb, nb);
    for (int t = 0; t < nb; ++t) {
      const int c = rows[nc + t];
      const int sc = supernode_of[static_cast<size_t>(c)];
      scatter(sc);
      const int ld = l.row_begin[sc + 1] - l.row_begin[sc];
      const double* col = z[static_cast<size_t>(sc)].data() + static_cast<long>(c - l.first_column[sc]) * ld;
      for (int u = t; u < nb; ++u) zrr(u, t) = zrr(t, u) = col[position_of[static_cast<size_t>(rows[nc + u])]];
    }
  };
  // The diagonal blocks: entry (k1, k2) of a pose's block is stored in column min(k1, k2).
  const auto storeDiagonal = [&](int s, int c0, int nc, const MutableBlock& zs) {
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
  };
  for (int s = l.supernodes - 1; s >= 0; --s) {
    const int c0 = l.first_column[s], nc = l.first_column[s + 1] - c0;
    const int nr = l.row_begin[s + 1] - l.row_begin[s], nb = nr - nc;
    const int* rows = l.rows + l.row_begin[s];
    const Block ls(l.values + l.value_begin[s], nr, nc);
    std::vector<double>& zbuf = z[static_cast<size_t>(s)];
    zbuf.resize(static_cast<size_t>(nr) * static_cast<size_t>(nc));
    MutableBlock zs(zbuf.data(), nr, nc);
    if (l.unit_diagonal_ldl) {
      if (nc != 1) throw std::invalid_argument("inverseDiagonalBlocks: an LDL' factor has one column per supernode");
      zs(0, 0) = 1.0 / ls(0, 0);
      if (nb > 0) {
        gather(nc, nb, rows);
        const auto wl = ls.bottomRows(nb);
        zrs.noalias() = -zrr * wl;
        zs.bottomRows(nb) = zrs;
        zs(0, 0) -= wl.col(0).dot(zrs.col(0));
      }
    } else {
      const auto lss = ls.topRows(nc).triangularView<Eigen::Lower>();
      Eigen::MatrixXd inv_lss = Eigen::MatrixXd::Identity(nc, nc);
      lss.solveInPlace(inv_lss);
      zs.topRows(nc).noalias() = inv_lss.transpose() * inv_lss;
      if (nb > 0) {
        gather(nc, nb, rows);
        w = ls.bottomRows(nb) * inv_lss;
        zrs.noalias() = -zrr * w;
        zs.bottomRows(nb) = zrs;
        zs.topRows(nc).noalias() -= w.transpose() * zrs;
      }
    }
    storeDiagonal(s, c0, nc, zs);
    for (int k = release_after.begin[static_cast<size_t>(s)]; k < release_after.begin[static_cast<size_t>(s) + 1]; ++k)
      std::vector<double>().swap(z[static_cast<size_t>(release_after.supernodes[static_cast<size_t>(k)])]);
  }
  return blocks;
}

}  // namespace urbanslam::esdf
