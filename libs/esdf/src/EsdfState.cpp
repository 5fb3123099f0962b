// The filter's state as bytes and back (Esdf::writeState, InformationState::write): every
// member that a later step reads, raw, so that a filter read back continues bit for bit as the
// one written would have. What is left out is rebuilt before any use: the window factor
// (refactorised by every recoverRecent) and the options (the reader's own).
#include <stdexcept>
#include <string>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {

namespace {

void writeInts(common::BinaryWriter& w, const std::vector<int>& v) {
  w.size(v.size());
  for (int x : v) w.i32(x);
}

std::vector<int> readInts(common::BinaryReader& r) {
  std::vector<int> v(r.count(4));
  for (int& x : v) x = r.i32();
  return v;
}

}  // namespace

void InformationState::write(common::BinaryWriter& w) const {
  w.size(rows_.size());
  for (const Row& row : rows_) {
    w.matrix(row.diag);
    w.matrix(row.eta);
    w.matrix(row.mean);
    w.size(row.links.size());
    for (const Link& l : row.links) {
      w.i32(l.other);
      w.matrix(l.block);
    }
  }
  w.u64(structure_stamp_);
  w.i64(link_count_);
}

void InformationState::read(common::BinaryReader& r) {
  constexpr size_t kRowBytes = (9 + 3 + 3) * 8 + 8, kLinkBytes = 4 + 9 * 8;
  std::deque<Row> rows(r.count(kRowBytes));
  long long links = 0;
  for (Row& row : rows) {
    row.diag = r.matrix<3, 3>();
    row.eta = r.matrix<3, 1>();
    row.mean = r.matrix<3, 1>();
    row.links.resize(r.count(kLinkBytes));
    for (Link& l : row.links) {
      l.other = r.i32();
      l.block = r.matrix<3, 3>();
    }
    links += static_cast<long long>(row.links.size());
  }
  // Every link has its mirror in the other row (addBlock relies on it).
  const int n = static_cast<int>(rows.size());
  for (int i = 0; i < n; ++i)
    for (const Link& l : rows[static_cast<size_t>(i)].links) {
      if (l.other < 0 || l.other >= n || l.other == i) r.fail("filter link " + std::to_string(i) + " -> " + std::to_string(l.other));
      bool mirrored = false;
      for (const Link& m : rows[static_cast<size_t>(l.other)].links) mirrored = mirrored || m.other == i;
      if (!mirrored) r.fail("filter link " + std::to_string(i) + " -> " + std::to_string(l.other) + " without its mirror");
    }
  structure_stamp_ = r.u64();
  link_count_ = r.i64();
  // Compared as links / 2 and parity: a count read from a file may be anything, and doubling it may overflow.
  if (link_count_ < 0 || links % 2 != 0 || link_count_ != links / 2) r.fail("filter link count");
  rows_ = std::move(rows);
}

void Esdf::writeState(common::BinaryWriter& w) const {
  state_.write(w);
  w.size(factors_.size());
  for (const Factor& f : factors_) {
    if (f.kind == Factor::Kind::Motion) throw std::logic_error("Esdf::writeState: motion-model factors cannot be saved");
    w.u8(static_cast<std::uint8_t>(f.kind));
    w.i32(f.a);
    w.i32(f.b);
    w.matrix(f.z);
    w.matrix(f.weight);
    w.f64(f.dt);
    w.matrix(f.lin_a);
    w.matrix(f.lin_b);
  }
  writeInts(w, first_factor_of_pose_);

  const SparseCholesky::Matrix m = full_factor_.matrix();
  w.boolean(!m.colptr.empty());
  if (!m.colptr.empty()) {
    w.i32(m.first);
    w.i32(m.last);
    w.u64(m.structure_stamp);
    writeInts(w, m.colptr);
    writeInts(w, m.rowind);
    w.size(m.values.size());
    for (double v : m.values) w.f64(v);
  }

  w.f64(unused_gate_slots_[0]);
  w.f64(unused_gate_slots_[1]);
  w.u64(values_stamp_);
  w.u64(full_factor_values_);
  w.i32(chain_base_);
  w.size(chain_phi_.size());
  for (const Mat3& p : chain_phi_) w.matrix(p);
  w.size(chain_cov_.size());
  for (const Mat3& c : chain_cov_) w.matrix(c);
  for (size_t k = 0; k < chain_phi_.size(); ++k) {
    w.i32(chain_root_[k]);
    w.i32(chain_lineage_[k]);
  }
  w.boolean(chain_valid_);
  w.dense(base_columns_);
  w.size(factors_at_factor_);
  w.boolean(explained_stamp_ == values_stamp_);
}

void Esdf::readState(common::BinaryReader& r, bool with_updates, bool with_lineages) {
  if (size() != 0) throw std::logic_error("Esdf::readState into a filter that has poses");
  state_.read(r);
  const int n = state_.size();

  constexpr size_t kFactorBytes = 1 + 4 + 4 + (3 + 9 + 1 + 3 + 3) * 8;
  factors_.resize(r.count(kFactorBytes));
  for (Factor& f : factors_) {
    const std::uint8_t kind = r.u8();
    if (kind != static_cast<std::uint8_t>(Factor::Kind::Prior) && kind != static_cast<std::uint8_t>(Factor::Kind::Relative))
      r.fail("filter factor of kind " + std::to_string(kind));
    f.kind = static_cast<Factor::Kind>(kind);
    f.a = r.i32();
    f.b = r.i32();
    const bool prior = f.kind == Factor::Kind::Prior;
    if (f.a < 0 || f.a >= n || (prior ? f.b != -1 : (f.b < 0 || f.b >= n || f.b == f.a)))
      r.fail("filter factor between poses " + std::to_string(f.a) + " and " + std::to_string(f.b) + " of " + std::to_string(n));
    f.z = r.matrix<3, 1>();
    f.weight = r.matrix<3, 3>();
    f.dt = r.f64();
    f.lin_a = r.matrix<3, 1>();
    f.lin_b = r.matrix<3, 1>();
  }
  first_factor_of_pose_ = readInts(r);
  if (first_factor_of_pose_.size() != static_cast<size_t>(n)) r.fail("filter pose table size");
  for (int f : first_factor_of_pose_)
    if (f < 0 || static_cast<size_t>(f) > factors_.size()) r.fail("filter pose table entry " + std::to_string(f));

  if (r.boolean()) {
    SparseCholesky::Matrix m;
    m.first = r.i32();
    m.last = r.i32();
    m.structure_stamp = r.u64();
    m.colptr = readInts(r);
    m.rowind = readInts(r);
    m.values.resize(r.count(8));
    for (double& v : m.values) v = r.f64();
    // The filter factorises all its poses, from the first (ensureFactor).
    if (m.first != 0 || m.last > n)
      r.fail("filter factorisation of poses [" + std::to_string(m.first) + ", " + std::to_string(m.last) + ")");
    try {
      full_factor_.factorize(m);
    } catch (const std::invalid_argument& e) {
      r.fail(std::string("filter factorisation: ") + e.what());
    } catch (const NotPositiveDefinite& e) {
      r.fail(std::string("filter factorisation: ") + e.what());
    }
  }

  unused_gate_slots_[0] = r.f64();
  unused_gate_slots_[1] = r.f64();
  values_stamp_ = r.u64();
  full_factor_values_ = r.u64();
  chain_base_ = r.i32();
  chain_phi_.resize(r.count(9 * 8));
  for (Mat3& p : chain_phi_) p = r.matrix<3, 3>();
  chain_cov_.resize(r.count(9 * 8));
  for (Mat3& c : chain_cov_) c = r.matrix<3, 3>();
  if (chain_base_ < 0 || chain_base_ > n || chain_phi_.size() != chain_cov_.size() ||
      chain_phi_.size() > static_cast<size_t>(n - chain_base_))
    r.fail("filter dead-reckoning chain");
  chain_root_.assign(chain_phi_.size(), chain_base_ - 1);
  chain_lineage_.assign(chain_phi_.size(), chain_base_);
  root_columns_.clear();
  for (size_t k = 0; with_lineages && k < chain_phi_.size(); ++k) {
    chain_root_[k] = r.i32();
    chain_lineage_[k] = r.i32();
    const int pose = chain_base_ + static_cast<int>(k);
    if (chain_root_[k] < 0 || chain_root_[k] >= chain_base_ || chain_lineage_[k] < chain_base_ || chain_lineage_[k] > pose)
      r.fail("filter dead-reckoning chain lineage");
    if (chain_root_[k] != chain_base_ - 1) root_columns_.emplace(chain_root_[k], Eigen::MatrixXd());
  }
  chain_valid_ = r.boolean();
  base_columns_ = r.dense();
  newFactor();
  anchor_base_ = -1;
  anchor_paths_from_ = -1;
  factors_of_pose_.clear();
  factors_indexed_ = 0;
  if (base_columns_.size() != 0 && (!full_factor_.valid() || base_columns_.rows() != 3 * full_factor_.last() || base_columns_.cols() != 3))
    r.fail("filter covariance columns");
  explained_stamp_ = ~std::uint64_t{0};
  if (with_updates) {
    factors_at_factor_ = r.size();
    if (factors_at_factor_ > factors_.size()) r.fail("filter factors since the factorisation");
    if (r.boolean()) explained_stamp_ = values_stamp_;
  }
}

}  // namespace urbanslam::esdf
