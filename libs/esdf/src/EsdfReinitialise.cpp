// Esdf::reinitialiseFromHeadings: a headings-first linearisation point (see Esdf.h).
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <stdexcept>
#include <string>
#include <vector>

#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Solves H dx = -g (H symmetric positive definite, given by its triplets).
Eigen::VectorXd solveNormalEquations(int n, const Triplets& h, const Eigen::VectorXd& g, const char* what) {
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(h.begin(), h.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(m);
  if (ldlt.info() != Eigen::Success) throw NotPositiveDefinite(std::string("information of the ") + what + " is not positive definite");
  return ldlt.solve(-g);
}

}  // namespace

long long Esdf::reinitialiseFromHeadings() {
  const int n = size();
  for (const Factor& f : factors_)
    if (f.kind == Factor::Kind::Motion) throw std::logic_error("reinitialiseFromHeadings: motion-model factors are not supported");

  // 1. Headings. A factor's heading error is linear in the two headings (slopes +-1 on its
  //    committed branch) and independent of the positions; its weight is the heading's own
  //    information, 1 / (W^-1)_phiphi (the translation errors left free).
  {
    Triplets h;
    h.reserve(factors_.size() * 4);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    for (const Factor& f : factors_) {
      const Linearisation l = linearise(f, state_.mean(f.a), f.b >= 0 ? state_.mean(f.b) : Vec3::Zero());
      const double w = 1.0 / l.w.inverse()(2, 2);
      const double ja = l.a_a(2, 2), e = l.e0.z();
      h.emplace_back(f.a, f.a, w * ja * ja);
      g(f.a) += w * ja * e;
      if (f.b < 0) continue;
      const double jb = l.a_b(2, 2);
      h.emplace_back(f.b, f.b, w * jb * jb);
      h.emplace_back(f.a, f.b, w * ja * jb);
      h.emplace_back(f.b, f.a, w * ja * jb);
      g(f.b) += w * jb * e;
    }
    const Eigen::VectorXd d = solveNormalEquations(n, h, g, "headings");
    for (int p = 0; p < n; ++p) {
      Vec3 x = state_.mean(p);
      x.z() += d(p);
      state_.setMean(p, x);
    }
  }
  // 2. Positions with the headings held: every factor's error is then linear in them, so one
  //    solve of the translation columns of the whole cost is exact.
  {
    Triplets h;
    h.reserve(factors_.size() * 16);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(2 * n);
    auto addBlock = [&h](int r, int c, const Eigen::Matrix2d& b) {
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) h.emplace_back(2 * r + i, 2 * c + j, b(i, j));
    };
    for (const Factor& f : factors_) {
      const Linearisation l = linearise(f, state_.mean(f.a), f.b >= 0 ? state_.mean(f.b) : Vec3::Zero());
      const Eigen::Matrix<double, 3, 2> ja = l.a_a.leftCols<2>();
      const Eigen::Matrix<double, 2, 3> jaw = ja.transpose() * l.w;
      addBlock(f.a, f.a, jaw * ja);
      g.segment<2>(2 * f.a) += jaw * l.e0;
      if (f.b < 0) continue;
      const Eigen::Matrix<double, 3, 2> jb = l.a_b.leftCols<2>();
      const Eigen::Matrix<double, 2, 3> jbw = jb.transpose() * l.w;
      addBlock(f.b, f.b, jbw * jb);
      const Eigen::Matrix2d ab = jaw * jb;
      addBlock(f.a, f.b, ab);
      addBlock(f.b, f.a, ab.transpose());
      g.segment<2>(2 * f.b) += jbw * l.e0;
    }
    const Eigen::VectorXd d = solveNormalEquations(2 * n, h, g, "positions");
    for (int p = 0; p < n; ++p) {
      Vec3 x = state_.mean(p);
      x.head<2>() += d.segment<2>(2 * p);
      state_.setMean(p, x);
    }
  }
  return relineariseMoved();
}

}  // namespace urbanslam::esdf
