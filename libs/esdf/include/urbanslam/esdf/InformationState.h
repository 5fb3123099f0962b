#pragma once
// The delayed state in information form (thesis eqs. 2.3-2.6): the information vector eta and a
// symmetric block-sparse information matrix Lambda of 3x3 blocks, one block row per pose, plus
// the current mean estimate mu.
//
// Storage is a block row per pose holding its diagonal block and a short list of links to the
// poses it shares information with. Adding a pose and linking it to its predecessor is O(1)
// (amortised), so the prediction step of the ESDF stays constant-time however long the
// trajectory; nothing here is dense in the number of poses.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <vector>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::common {
class BinaryWriter;
class BinaryReader;
}  // namespace urbanslam::common

namespace urbanslam::esdf {

class InformationState {
 public:
  struct Link {
    int other;
    Mat3 block;  // Lambda(this, other); the mirror block Lambda(other, this) is its transpose
  };

  int size() const { return static_cast<int>(rows_.size()); }

  // Appends a pose with zero information and the given mean; returns its index.
  int addPose(const Vec3& mean);

  const Mat3& diagonal(int i) const { return rows_[i].diag; }
  void addDiagonal(int i, const Mat3& m) { rows_[i].diag += m; }
  // Lambda(i, j) += m and Lambda(j, i) += m' (i != j); creates the link when absent.
  void addBlock(int i, int j, const Mat3& m);
  // Lambda(i, j), zero when the poses share no information.
  Mat3 block(int i, int j) const;
  const std::vector<Link>& links(int i) const { return rows_[i].links; }

  const Vec3& eta(int i) const { return rows_[i].eta; }
  void addEta(int i, const Vec3& v) { rows_[i].eta += v; }
  const Vec3& mean(int i) const { return rows_[i].mean; }
  void setMean(int i, const Vec3& m) { rows_[i].mean = m; }

  // Marginalises pose k out (Schur complement onto its neighbours) and removes it; poses after
  // k shift down by one. Costs O(degree(k)^2 + size() - k): constant when k is a recent pose,
  // which is how prediction without augmentation uses it.
  void marginalise(int k);

  // Number of structural changes (poses or links added/removed): a factorisation whose
  // structure stamp matches can reuse its symbolic analysis.
  std::uint64_t structureStamp() const { return structure_stamp_; }
  // Total number of stored off-diagonal links (each pair counted once).
  long long linkCount() const { return link_count_; }
  // Bytes held by the block rows (for the memory-per-pose figure of the benchmarks).
  size_t memoryBytes() const;

  // Every row exactly as held, links in their order (sums over them depend on it), and the
  // stamps (EsdfState.cpp). read() replaces this state; it throws common::InputError (through
  // the reader) for links that point outside the state or lack their mirror.
  void write(common::BinaryWriter& w) const;
  void read(common::BinaryReader& r);

  // Dense copies for tests and small problems only (O(size^2)).
  Eigen::MatrixXd denseInformation() const;
  Eigen::VectorXd denseEta() const;
  Eigen::VectorXd denseMean() const;

 private:
  struct Row {
    Mat3 diag = Mat3::Zero();
    Vec3 eta = Vec3::Zero();
    Vec3 mean = Vec3::Zero();
    std::vector<Link> links;
  };
  Link* findLink(int i, int j);

  // One per pose, up to millions: grown by fixed blocks (a vector's doubling leaves up to half
  // its capacity unused and holds three times its size while it moves).
  std::deque<Row> rows_;
  std::uint64_t structure_stamp_ = 0;
  long long link_count_ = 0;
};

}  // namespace urbanslam::esdf
