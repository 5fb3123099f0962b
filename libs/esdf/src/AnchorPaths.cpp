// Conservative covariances through the newest closure (Esdf::conservativeJoint): how a factored
// pose is reached from the closure's factored end by the factors alone on the path between them,
// and how one relative factor carries a pose and its noise to the pose at its other end.
#include <Eigen/LU>
#include <queue>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

void Esdf::indexFactors() {
  factors_of_pose_.resize(static_cast<size_t>(size()));
  for (; factors_indexed_ < factors_.size(); ++factors_indexed_) {
    const Factor& f = factors_[factors_indexed_];
    if (f.kind != Factor::Kind::Relative) continue;  // a prior links nothing; motion factors: not on such paths
    factors_of_pose_[static_cast<size_t>(f.a)].push_back(static_cast<int>(factors_indexed_));
    factors_of_pose_[static_cast<size_t>(f.b)].push_back(static_cast<int>(factors_indexed_));
  }
}

void Esdf::factorStep(const Factor& f, bool from_a, Mat3* d_x, Mat3* d_e) {
  // x_b = x_a ⊕ z ⊕ e, e ~ N(0, weight^-1) (the error ⊖z ⊕ (⊖x_a ⊕ x_b)), linearised where the
  // factor is; from b, x_a = x_b ⊕ (z ⊕ e)^-1.
  if (from_a) {
    composeJacobians(f.lin_a, f.z, d_x, nullptr);
    composeJacobians(compose(f.lin_a, f.z), Vec3::Zero(), nullptr, d_e);
    return;
  }
  Mat3 d_inv, d_z;
  composeJacobians(f.lin_b, inverse(f.z), d_x, &d_inv);
  composeJacobians(f.z, Vec3::Zero(), nullptr, &d_z);
  *d_e = d_inv * inverseJacobian(f.z) * d_z;
}

void Esdf::PathSearch::start(int pose) {
  from = pose;
  paths.clear();
  settled.clear();
  open = {};
  paths[pose] = PathBound{};
  open.push({0.0, pose, 0});
}

void Esdf::searchPaths(PathSearch& s, int to, size_t max_poses, int below) {
  // Every path bounds the relative pose: the tightest is looked for (Dijkstra on the spread of
  // the accumulated position noise), over paths of at most kAnchorPathLinks factors, and only as
  // far as the poses asked need (a settled pose's path does not depend on when it was asked).
  while (!s.settled.count(to) && !s.open.empty() && s.settled.size() < max_poses) {
    const PathEntry e = s.open.top();
    s.open.pop();
    if (!s.settled.insert(e.pose).second || e.links >= kAnchorPathLinks) continue;
    const PathBound bu = s.paths.at(e.pose);  // a copy: the map grows below
    for (const int k : factors_of_pose_[static_cast<size_t>(e.pose)]) {
      const Factor& f = factors_[static_cast<size_t>(k)];
      const bool forward = f.a == e.pose;
      const int v = forward ? f.b : f.a;
      if (v >= below || s.settled.count(v)) continue;
      Mat3 d_x, d_e;
      factorStep(f, forward, &d_x, &d_e);
      const PathBound nv{d_x * bu.phi, d_x * bu.cov * d_x.transpose() + d_e * f.weight.inverse() * d_e.transpose()};
      const double spread = nv.cov(0, 0) + nv.cov(1, 1);
      const auto known = s.paths.find(v);
      if (known != s.paths.end() && known->second.cov(0, 0) + known->second.cov(1, 1) <= spread) continue;
      s.paths[v] = nv;
      s.open.push({spread, v, e.links + 1});
    }
  }
}

const Esdf::PathBound* Esdf::anchorPath(int p) {
  const int from = anchor_.a, m = chain_base_;
  if (anchor_paths_from_ != from || anchor_paths_base_ != m) {
    anchor_paths_from_ = from;
    anchor_paths_base_ = m;
    indexFactors();
    anchor_search_.start(from);
  }
  searchPaths(anchor_search_, p, kAnchorPathPoses, m);
  // Settled, or the best path found before the search ran out (a bound all the same).
  const auto it = anchor_search_.paths.find(p);
  return it == anchor_search_.paths.end() ? nullptr : &it->second;
}

bool Esdf::pathRelativeCovariance(int i, int j, Mat3* cov, size_t max_poses) {
  if (i < 0 || j < 0 || i >= size() || j >= size() || i == j) throw std::out_of_range("pathRelativeCovariance: bad poses");
  PathSearch& s = path_search_;
  if (s.stamp != values_stamp_ || (s.from != i && s.from != j)) {
    indexFactors();
    s.stamp = values_stamp_;
    s.start(j);
  }
  const int to = s.from == j ? i : j;
  searchPaths(s, to, max_poses, size());
  const auto it = s.paths.find(to);
  if (it == s.paths.end()) return false;
  // The relative pose moves only with the path's noise on the far pose (the searched-from pose
  // moves both ends rigidly).
  Mat3 ja, jb;
  betweenJacobians(state_.mean(i), state_.mean(j), &ja, &jb);
  const Mat3& d = to == i ? ja : jb;
  *cov = d * it->second.cov * d.transpose();
  return true;
}

}  // namespace urbanslam::esdf
