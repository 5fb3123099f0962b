#pragma once
// State and covariance recovery for the information filter: a CHOLMOD (SuiteSparse) sparse
// Cholesky factorisation of Lambda, or of the principal sub-block of a range of poses, with a
// fill-reducing ordering (AMD by default; METIS's nested dissection as well where AMD's factor
// would be dear: it pays off on very large grid-like graphs, such as a city's streets driven many
// times). The symbolic analysis is reused while the block structure is unchanged, which is the
// case between relinearisation passes.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "urbanslam/esdf/InformationState.h"

namespace urbanslam::esdf {

struct SupernodalFactorView;
struct FactorIndex;

// Lambda (or the factorised block of it) is not numerically positive definite: the information
// added so far is inconsistent or too extreme for double precision. Callers that fed the filter
// from a file turn it into an error naming the measurement.
class NotPositiveDefinite : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class FillReducingOrdering {
  Amd,     // approximate minimum degree
  Metis,   // METIS nested dissection
  Auto,    // CHOLMOD's default strategy (AMD, then METIS when AMD's fill is high)
  Natural  // pose order (no reordering; for comparisons)
};

// L^-1 P e_p for the three columns of one pose p (A = P' L L' P, SparseCholesky::pathSolve):
// non-zero only on the pose's path to the root of L's elimination tree, held as the rows of
// the supernodes there. Two of them give the covariance block between their poses.
struct PathSolution {
  int pose = -1;
  std::vector<int> supernodes;  // ascending
  std::vector<int> begin;       // each supernode's first row in values (one more at the end)
  std::vector<double> values;   // three per row: the pose's three columns
  double work = 0;              // multiply-adds the solve took (its supernodes' entries, three columns)
};

class SparseCholesky {
 public:
  // With AMD, `nested_dissection_min_flops` > 0: a pattern whose AMD factorisation would take at
  // least that many floating-point operations (CHOLMOD's count from the analysis) is ordered by
  // METIS too, and the ordering with fewer operations is used. On a city driven many times the
  // factor of the whole map is where memory peaks, and nested dissection's is the smaller; on
  // small and chain-like graphs AMD's is as good and METIS's analysis is the dearer.
  explicit SparseCholesky(FillReducingOrdering ordering = FillReducingOrdering::Amd, double nested_dissection_min_flops = 0);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // Factorises Lambda restricted to poses [first, last). Throws NotPositiveDefinite when the
  // block is not positive definite (an unanchored or inconsistent problem).
  void factorize(const InformationState& state, int first, int last);
  bool valid() const;
  int first() const { return first_; }
  int last() const { return last_; }
  // Stamp of the InformationState structure the factor was computed for.
  std::uint64_t structureStamp() const { return stamp_; }

  // Solves Lambda_sub x = b (b has 3*(last-first) rows and any number of columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  // Non-zeros of the factor L (for statistics).
  long long factorNonZeros() const;
  // The 3x3 diagonal blocks of Lambda_sub^-1, one per pose of the range: the marginal
  // covariances, all at once for about the cost of one more factorisation (SparseInverse.h).
  std::vector<Mat3> inverseDiagonalBlocks() const;
  // The multiply-adds inverseDiagonalBlocks takes on this factor (its supernodes' products), to
  // weigh it against path solves (PathSolution::work) of the poses actually asked for.
  double inverseWork() const;
  // The multiply-adds of a numeric factorisation of this factor's pattern (per supernode: its
  // diagonal block's Cholesky, the solve below it, the update of its ancestors).
  double factorisationWork() const;
  bool supernodal() const;
  // The factor's ordering is METIS's nested dissection (chosen over AMD, or asked for).
  bool nestedDissection() const;
  // Covariance blocks among a few poses of the range (indices from first()) at the cost of their
  // paths in the factor, not of column solves over all of it (PathSolve.h): pathSolve once per
  // pose, then covarianceBetween(a, b) = Sigma(a, b) for any two of them.
  PathSolution pathSolve(int pose) const;
  static Mat3 covarianceBetween(const PathSolution& a, const PathSolution& b);

  // The matrix the current factor was computed from (lower triangle, compressed columns), kept
  // so that a saved filter can rebuild exactly this factor: a covariance from an older
  // factorisation (CovarianceMode::Conservative) must not change across a save and a load.
  struct Matrix {
    int first = 0, last = 0;
    std::uint64_t structure_stamp = 0;
    std::vector<int> colptr, rowind;
    std::vector<double> values;
  };
  // Empty (colptr empty) when there is no factor.
  Matrix matrix() const;
  // Factorises `m` as factorize() did (same analysis, same numbers). Throws std::invalid_argument
  // for a malformed matrix, NotPositiveDefinite like factorize().
  void factorize(const Matrix& m);

 private:
  // The factor as the sparse inverse and the path solves read it (a simplicial one packed in place).
  SupernodalFactorView view() const;
  const FactorIndex& index(const SupernodalFactorView& v) const;
  void factorizeLower(std::vector<int> colptr, std::vector<int> rowind, std::vector<double> values);

  struct Impl;
  std::unique_ptr<Impl> impl_;
  int first_ = 0, last_ = 0;
  std::uint64_t stamp_ = ~std::uint64_t{0};
};

}  // namespace urbanslam::esdf
