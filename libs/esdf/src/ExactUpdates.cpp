// Exact covariances between factorisations. The innovation gate needs the exact covariance of a
// closure's two poses whenever its conservative bound admits it; driving along an earlier visit,
// the closures come one per keyframe, and refactorising the whole map for each (then its sparse
// inverse for the next candidates) made the gate's cost per keyframe grow with the map. Since
// the last factorisation Lambda changed only by the chain's links (each pose added from its
// predecessor: exact dead reckoning, as the conservative covariance has it) and a few closures,
// each a rank-3 term H' W H. Woodbury then gives the current covariance from the old one:
//   (Lambda_c + H' W H)^-1 = Sigma_c - Sigma_c H' (I + W H Sigma_c H')^-1 W H Sigma_c,
// which needs Sigma_c only among the poses of the closures and of the asked pair: path solves
// of the old factor for the factored ones (PathSolve.h; kept until the next factorisation), the
// chain's propagation for the newer ones.
#include <Eigen/LU>
#include <algorithm>

#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {

namespace {
// Poses new to one query beyond this, and the factorisation is due. (Their path solves cost a
// small part of the factor each, PathSolve.h; but a refactorisation also tightens the
// conservative covariances that pick the loop-closure candidates, which come from the last
// factorisation.)
constexpr size_t kMaxNewSolvedPoses = 4;
// The update's dense system is 3K square: closures since the factorisation beyond this, and the
// factorisation is due anyway.
constexpr size_t kMaxUpdateFactors = 64;
}  // namespace

void Esdf::solveInvolved(const std::vector<int>& poses) {
  if (poses.empty()) return;
  const int k = static_cast<int>(involved_.size());
  const int u = static_cast<int>(poses.size());
  for (int p : poses) {
    involved_at_[p] = static_cast<int>(involved_.size());
    involved_.push_back(p);
    involved_paths_.push_back(full_factor_.pathSolve(p));
  }
  Eigen::MatrixXd grown(3 * (k + u), 3 * (k + u));
  grown.topLeftCorner(3 * k, 3 * k) = involved_cov_;
  for (int c = k; c < k + u; ++c)
    for (int b = 0; b <= c; ++b) {
      const Mat3 s = SparseCholesky::covarianceBetween(involved_paths_[static_cast<size_t>(b)], involved_paths_[static_cast<size_t>(c)]);
      grown.block<3, 3>(3 * b, 3 * c) = s;
      grown.block<3, 3>(3 * c, 3 * b) = s.transpose();
    }
  involved_cov_ = std::move(grown);
}

bool Esdf::updatedJoint(int i, int j, Mat6* joint) {
  Eigen::MatrixXd s;
  if (!updatedCovariance({i, j}, &s)) return false;
  *joint = s;
  return true;
}

bool Esdf::updatedCovariance(const std::vector<int>& targets, Eigen::MatrixXd* cov) {
  if (!full_factor_.valid() || explained_stamp_ != values_stamp_ || !conservativeReady()) return false;
  const int m = chain_base_;
  struct Update {
    int a, b;  // b = -1: a prior
    Mat3 ja, jb, w;
  };
  std::vector<Update> updates;
  for (size_t k = factors_at_factor_; k < factors_.size(); ++k) {
    const Factor& f = factors_[k];
    const int newer = std::max(f.a, f.b);
    if (newer >= m && first_factor_of_pose_[static_cast<size_t>(newer)] == static_cast<int>(k)) continue;  // a chain link
    if (f.kind == Factor::Kind::Motion || updates.size() == kMaxUpdateFactors) return false;
    const Linearisation l = linearise(f, f.lin_a, f.lin_b);  // what contribution() added
    updates.push_back({f.a, f.kind == Factor::Kind::Prior ? -1 : f.b, l.a_a, l.a_b, l.w});
  }
  std::vector<int> unsolved;
  const auto need = [&](int p) {
    if (p >= 0 && p < m && !involved_at_.count(p) && std::find(unsolved.begin(), unsolved.end(), p) == unsolved.end())
      unsolved.push_back(p);
  };
  for (int t : targets) need(t);
  for (const Update& u : updates) {
    need(u.a);
    need(u.b);
  }
  if (unsolved.size() > kMaxNewSolvedPoses) return false;
  solveInvolved(unsolved);

  const int n_u = static_cast<int>(updates.size());
  const int n_t = static_cast<int>(targets.size());
  // H_u Sigma_c(., t) for update u and pose t.
  const auto hs = [&](const Update& u, int t) -> Mat3 {
    Mat3 r = u.ja * chainedCovariance(u.a, t);
    if (u.b >= 0) r += u.jb * chainedCovariance(u.b, t);
    return r;
  };
  const auto target = [&](int a) { return targets[static_cast<size_t>(a)]; };
  Eigen::MatrixXd s(3 * n_t, 3 * n_t);
  for (int a = 0; a < n_t; ++a)
    for (int b = 0; b < n_t; ++b) s.block<3, 3>(3 * a, 3 * b) = chainedCovariance(target(a), target(b));
  if (n_u > 0) {
    Eigen::MatrixXd hsh(3 * n_u, 3 * n_u), hst(3 * n_u, 3 * n_t), w_hst(3 * n_u, 3 * n_t), m_mat(3 * n_u, 3 * n_u);
    for (int k = 0; k < n_u; ++k) {
      const Update& uk = updates[static_cast<size_t>(k)];
      for (int l = 0; l < n_u; ++l) {
        const Update& ul = updates[static_cast<size_t>(l)];
        Mat3 b = hs(uk, ul.a) * ul.ja.transpose();
        if (ul.b >= 0) b += hs(uk, ul.b) * ul.jb.transpose();
        hsh.block<3, 3>(3 * k, 3 * l) = b;
      }
      for (int t = 0; t < n_t; ++t) hst.block<3, 3>(3 * k, 3 * t) = hs(uk, target(t));
    }
    // I + W H Sigma_c H' and W H Sigma_c E_T, W block-diagonal.
    for (int k = 0; k < n_u; ++k) {
      const Mat3& w = updates[static_cast<size_t>(k)].w;
      m_mat.middleRows(3 * k, 3) = w * hsh.middleRows(3 * k, 3);
      w_hst.middleRows(3 * k, 3) = w * hst.middleRows(3 * k, 3);
    }
    m_mat += Eigen::MatrixXd::Identity(3 * n_u, 3 * n_u);
    s -= hst.transpose() * m_mat.partialPivLu().solve(w_hst);
  }
  *cov = 0.5 * (s + s.transpose());
  return true;
}

}  // namespace urbanslam::esdf
