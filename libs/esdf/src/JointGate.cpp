// The joint innovation gate of two closures (the joint compatibility of Neira & Tardós, for a
// pair). Where the estimate has drifted a little beyond what its covariance admits, every
// alignment of a revisit lands just outside the single gate, each refused alone although they
// all measure the same correction. Two independent wrong alignments rarely agree; two true ones
// do, and their stacked innovation then costs little more than one of them: against the 6-dof
// quantile (16.8 at 0.99, where one closure has 11.3) the pair passes where each one alone did
// not. Two closures that disagree pay both innovations and fail.
#include <Eigen/LU>
#include <algorithm>
#include <stdexcept>

#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {

Eigen::MatrixXd Esdf::covarianceAmong(const std::vector<int>& poses) {
  for (int p : poses)
    if (p < 0 || p >= size()) throw std::out_of_range("covarianceAmong: bad pose");
  // Between factorisations, the last factor with the closures since (ExactUpdates.cpp), as the
  // single gate takes it: a pair tested at every keyframe of a long revisit would otherwise
  // refactorise the whole map each time. Else path solves of a current factor (PathSolve.h):
  // each pose's path in the factor's elimination tree, not a column solve over the whole map.
  if (Eigen::MatrixXd s; !factorCurrent() && updatedCovariance(poses, &s)) return s;
  ensureFactor();
  const size_t k = poses.size();
  std::vector<PathSolution> paths;
  paths.reserve(k);
  for (int p : poses) paths.push_back(full_factor_.pathSolve(p));
  Eigen::MatrixXd s(3 * k, 3 * k);
  for (size_t a = 0; a < k; ++a)
    for (size_t b = a; b < k; ++b) {
      const Mat3 c = SparseCholesky::covarianceBetween(paths[a], paths[b]);
      s.block<3, 3>(3 * a, 3 * b) = c;
      s.block<3, 3>(3 * b, 3 * a) = c.transpose();
    }
  return s;
}

GateResult Esdf::gateRelativePair(int i1, int j1, const Vec3& z1, const Mat3& omega1, int i2, int j2, const Vec3& z2, const Mat3& omega2) {
  if (i1 == j1 || i2 == j2) throw std::out_of_range("gateRelativePair: a pose with itself");
  std::vector<int> poses{i1, j1, i2, j2};
  std::sort(poses.begin(), poses.end());
  poses.erase(std::unique(poses.begin(), poses.end()), poses.end());
  const Eigen::MatrixXd sigma = covarianceAmong(poses);
  const auto at = [&](int p) { return 3 * static_cast<int>(std::lower_bound(poses.begin(), poses.end(), p) - poses.begin()); };
  // e = ⊖z ⊕ (⊖x_i ⊕ x_j) with its Jacobians in the poses, as the single gate takes it: the
  // innovation is -e, its covariance H Sigma H' + R with R = Omega^-1 per closure.
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(6, sigma.cols());
  Eigen::VectorXd nu(6);
  const auto row = [&](int r, int i, int j, const Vec3& z) {
    Mat3 ja, jb;
    nu.segment<3>(r) = -relativePoseError(state_.mean(i), state_.mean(j), z, &ja, &jb);
    h.block<3, 3>(r, at(i)) += ja;
    h.block<3, 3>(r, at(j)) += jb;
  };
  row(0, i1, j1, z1);
  row(3, i2, j2, z2);
  Eigen::MatrixXd s = h * sigma * h.transpose();
  s.block<3, 3>(0, 0) += omega1.inverse();
  s.block<3, 3>(3, 3) += omega2.inverse();
  return mahalanobisGateAt(nu, s, joint_gate_threshold_);
}

}  // namespace urbanslam::esdf
