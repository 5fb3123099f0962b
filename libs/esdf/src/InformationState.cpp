#include "urbanslam/esdf/InformationState.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

namespace urbanslam::esdf {

int InformationState::addPose(const Vec3& mean) {
  Row r;
  r.mean = mean;
  // Two links (predecessor, successor) are the common case; reserving them avoids regrowth.
  r.links.reserve(2);
  rows_.push_back(std::move(r));
  ++structure_stamp_;
  return size() - 1;
}

InformationState::Link* InformationState::findLink(int i, int j) {
  for (Link& l : rows_[i].links)
    if (l.other == j) return &l;
  return nullptr;
}

void InformationState::addBlock(int i, int j, const Mat3& m) {
  if (i == j) throw std::invalid_argument("addBlock: use addDiagonal for i == j");
  if (Link* l = findLink(i, j)) {
    l->block += m;
    findLink(j, i)->block += m.transpose();
    return;
  }
  // Beyond the two reserved, a row grows by one link at a time: a doubling vector left up to
  // half its capacity unused in every row a loop closure reached (tens of bytes per pose).
  for (const int r : {i, j})
    if (auto& ls = rows_[r].links; ls.size() == ls.capacity()) ls.reserve(ls.size() + 1);
  rows_[i].links.push_back({j, m});
  rows_[j].links.push_back({i, m.transpose()});
  ++structure_stamp_;
  ++link_count_;
}

Mat3 InformationState::block(int i, int j) const {
  if (i == j) return rows_[i].diag;
  for (const Link& l : rows_[i].links)
    if (l.other == j) return l.block;
  return Mat3::Zero();
}

void InformationState::marginalise(int k) {
  // Lambda_nn -= Lambda_nk Lambda_kk^-1 Lambda_kn and eta_n -= Lambda_nk Lambda_kk^-1 eta_k over
  // the neighbours n of k: the exact marginal of the remaining poses in information form.
  Row removed = std::move(rows_[k]);
  Eigen::LDLT<Mat3> kk(removed.diag);
  std::vector<Mat3> gain;  // Lambda_kk^-1 Lambda_kn for each neighbour n
  gain.reserve(removed.links.size());
  for (const Link& l : removed.links) gain.push_back(kk.solve(l.block));  // l.block = Lambda(k, n)
  const Vec3 kk_eta = kk.solve(removed.eta);
  for (size_t a = 0; a < removed.links.size(); ++a) {
    const int na = removed.links[a].other;
    const Mat3& lak = removed.links[a].block.transpose();  // Lambda(na, k)
    rows_[na].eta -= lak * kk_eta;
    rows_[na].diag -= lak * gain[a];
    for (size_t b = a + 1; b < removed.links.size(); ++b) addBlock(na, removed.links[b].other, -lak * gain[b]);
    // Drop na's link to k.
    auto& ls = rows_[na].links;
    ls.erase(std::remove_if(ls.begin(), ls.end(), [k](const Link& l) { return l.other == k; }), ls.end());
    --link_count_;
  }
  rows_.erase(rows_.begin() + k);
  // Renumber: only rows after k and their neighbours can hold an index > k, so for a recent k
  // this touches a handful of rows instead of the whole trajectory.
  std::vector<int> touched;
  for (int i = k; i < size(); ++i) {
    touched.push_back(i);
    for (const Link& l : rows_[i].links)
      if (l.other < k) touched.push_back(l.other);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (int i : touched)
    for (Link& l : rows_[i].links)
      if (l.other > k) --l.other;
  ++structure_stamp_;
}

size_t InformationState::memoryBytes() const {
  size_t bytes = rows_.size() * sizeof(Row);  // grown by fixed blocks: its size, to a block
  for (const Row& r : rows_) bytes += r.links.capacity() * sizeof(Link);
  return bytes;
}

Eigen::MatrixXd InformationState::denseInformation() const {
  const int n = size();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i) {
    m.block<3, 3>(3 * i, 3 * i) = rows_[i].diag;
    for (const Link& l : rows_[i].links) m.block<3, 3>(3 * i, 3 * l.other) = l.block;
  }
  return m;
}

Eigen::VectorXd InformationState::denseEta() const {
  Eigen::VectorXd v(3 * size());
  for (int i = 0; i < size(); ++i) v.segment<3>(3 * i) = rows_[i].eta;
  return v;
}

Eigen::VectorXd InformationState::denseMean() const {
  Eigen::VectorXd v(3 * size());
  for (int i = 0; i < size(); ++i) v.segment<3>(3 * i) = rows_[i].mean;
  return v;
}

}  // namespace urbanslam::esdf
