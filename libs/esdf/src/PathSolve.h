#pragma once
// Covariance blocks between a few poses without a pass over the whole factor. With
// A = P' L L' P, Sigma = A^-1 = (L^-1 P)' (L^-1 P), so the block between poses a and b is
// y_a' y_b with y_p = L^-1 P e_p (e_p: the pose's three unit columns). A forward solve from a
// unit column touches only the column's ancestors in L's elimination tree: y_p is non-zero on
// the pose's path to the root and costs that path (the supernodes above it), where a column
// solve passes over all of L twice. The innovation gate asks for a few such blocks at a time.
#include <vector>

#include "SparseInverse.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/esdf/Recovery.h"

namespace urbanslam::esdf {

// y_p for pose p (rows 3p .. 3p + 2 of A), scaled so that the covariance is a plain product
// (a unit-diagonal LDL' factor's D^-1/2 folded in). `offset_of`: a workspace of one entry per
// supernode, all -1, left so (a solve costs its path, not the number of supernodes).
PathSolution pathSolve(const SupernodalFactorView& l, const FactorIndex& index, std::vector<int>& offset_of, int pose);

// Sigma(a, b) (a's rows, b's columns) from the two poses' path solutions.
Mat3 pathCovariance(const PathSolution& a, const PathSolution& b);

}  // namespace urbanslam::esdf
