#pragma once
// Entries of A^-1 on the pattern of A's Cholesky factor L (the "sparse inverse subset"), by the
// Takahashi recurrences run backwards over L's supernodes. Every 3x3 diagonal block of A^-1
// lies in that pattern, so all the poses' marginal covariances cost about one more
// factorisation, where a column solve per pose costs a pass over the whole factor each.
#include <vector>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

// A lower-triangular factor L (A = P' L L' P) in supernodal form. Supernode s holds the columns
// [first_column[s], first_column[s + 1]); its row indices rows[row_begin[s] .. row_begin[s + 1])
// start with those columns in order, then the rows below them in ascending order; its values
// are a column-major block of (row count) x (column count) at values[value_begin[s]], of which
// the lower triangle of the top square and everything below it are L. A simplicial factor is
// the same with one column per supernode. perm[k] is the row of A that L's row k stands for.
// A simplicial LDL' factor (A = P' L D L' P, L with a unit diagonal) is read as it is stored,
// one column per supernode with D's entry in place of L's diagonal (unit_diagonal_ldl): its
// recurrences are the LL' ones with W = L_RS and (L_SS L_SS')^-1 = 1 / D, so no LL' copy of the
// factor is made to read it.
struct SupernodalFactorView {
  bool unit_diagonal_ldl = false;
  int columns = 0;
  int supernodes = 0;
  const int* first_column = nullptr;
  const int* row_begin = nullptr;
  const int* rows = nullptr;
  const int* value_begin = nullptr;
  const double* values = nullptr;
  const int* perm = nullptr;
};

// Where a factor's columns and rows lie: the supernode of each column of L, and L's row for each
// row of A (the inverse of the view's permutation). Built once per factorisation and shared by
// the sparse inverse and the path solves (PathSolve.h).
struct FactorIndex {
  std::vector<int> supernode_of, row_of;
  explicit FactorIndex(const SupernodalFactorView& l);
};

// The 3x3 diagonal blocks of A^-1 for A of size 3 * poses (rows 3p .. 3p + 2 are pose p).
std::vector<Mat3> inverseDiagonalBlocks(const SupernodalFactorView& l, const FactorIndex& index);
// Its multiply-adds: per supernode of nc columns over nb rows below them, Z_RS = -Z_RR W (nb² nc),
// W = L_RS L_SS^-1 and W' Z_RS (nb nc² each), L_SS^-1 (nc³ / 3).
double inverseWork(const SupernodalFactorView& l);
// A numeric factorisation's: per supernode nc³ / 3 (its diagonal block), nb nc² (the rows below)
// and nb² nc / 2 (the update of the ancestors it reaches).
double factorisationWork(const SupernodalFactorView& l);

}  // namespace urbanslam::esdf
