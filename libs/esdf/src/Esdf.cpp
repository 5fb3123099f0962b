#include "urbanslam/esdf/Esdf.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

Esdf::Esdf(EsdfOptions options)
    : options_(options),
      full_factor_(options.ordering, options.nested_dissection_min_flops),
      joint_gate_threshold_(chi2Quantile(options.chi2_gate_probability, 6)),
      single_gate_threshold_(chi2Quantile(options.chi2_gate_probability, 3)) {}
Esdf::~Esdf() = default;

void Esdf::reserve(int poses) { first_factor_of_pose_.reserve(static_cast<size_t>(poses)); }

Vec3 Esdf::stabilisingNoise(const MotionModel& m) const {
  // Three-input models have a full-rank F_u Q_v F_u' and need no stabilisation.
  if (m.inputDimension() >= 3) return Vec3::Zero();
  return {options_.stabilising_noise_xy_m2, options_.stabilising_noise_xy_m2, options_.stabilising_noise_phi_rad2};
}

Vec3 Esdf::relativeError(const Factor& f, const Vec3& xa, const Vec3& xb, Mat3* ja, Mat3* jb) const {
  Vec3 e = relativePoseError(xa, xb, f.z, ja, jb);
  if (options_.commit_heading_branch) e.z() = xb.z() - xa.z() - f.z.z();
  return e;
}

Esdf::Linearisation Esdf::linearise(const Factor& f, const Vec3& xa, const Vec3& xb) const {
  Linearisation l;
  switch (f.kind) {
    case Factor::Kind::Prior:
      l.e0 = poseDifference(xa, f.z);
      l.a_a.setIdentity();
      l.a_b.setZero();
      l.w = f.weight;
      break;
    case Factor::Kind::Motion: {
      const int dim = f.model->inputDimension();
      Mat3 fx;
      MatU fu;
      const Vec3 pred = f.model->predict(xa, f.z.head(dim), f.dt, &fx, &fu);
      // e = x_b - f(x_a, u): Lambda gets [F' W F, -F' W; -W F, W] (the ESDF augmentation).
      l.e0 = poseDifference(xb, pred);
      l.a_a = -fx;
      l.a_b.setIdentity();
      l.w = processInformation(fu, f.weight.topLeftCorner(dim, dim), stabilisingNoise(*f.model));
      break;
    }
    case Factor::Kind::Relative:
      l.e0 = relativeError(f, xa, xb, &l.a_a, &l.a_b);
      l.w = f.weight;
      break;
  }
  return l;
}

Esdf::Contribution Esdf::contribution(const Factor& f) const {
  const Linearisation l = linearise(f, f.lin_a, f.lin_b);
  // Linear model e(x) ~ A x - c with c = A lin - e0: Lambda += A' W A, eta += A' W c.
  Contribution c;
  const Mat3 atw = l.a_a.transpose() * l.w;
  c.aa = atw * l.a_a;
  if (f.kind == Factor::Kind::Prior) {
    c.eta_a = atw * (l.a_a * f.lin_a - l.e0);
    return c;
  }
  const Vec3 wc = l.w * (l.a_a * f.lin_a + l.a_b * f.lin_b - l.e0);
  const Mat3 btw = l.a_b.transpose() * l.w;
  c.bb = btw * l.a_b;
  c.ab = atw * l.a_b;
  c.eta_a = l.a_a.transpose() * wc;
  c.eta_b = l.a_b.transpose() * wc;
  return c;
}

void Esdf::add(const Factor& f, const Contribution& c) {
  state_.addDiagonal(f.a, c.aa);
  state_.addEta(f.a, c.eta_a);
  if (f.kind != Factor::Kind::Prior) {
    state_.addDiagonal(f.b, c.bb);
    state_.addBlock(f.a, f.b, c.ab);
    state_.addEta(f.b, c.eta_b);
  }
  markChanged();
}

void Esdf::apply(const Factor& f, double sign) {
  Contribution c = contribution(f);
  if (sign != 1.0) c.scale(sign);
  add(f, c);
}

void Esdf::addFactor(Factor f) {
  const bool explained = explained_stamp_ == values_stamp_;
  apply(f, +1.0);
  factors_.push_back(std::move(f));
  if (explained) explained_stamp_ = values_stamp_;  // still the factor plus what came after it
}

int Esdf::initialise(const Vec3& mean, const Mat3& covariance) {
  if (state_.size() != 0) throw std::logic_error("Esdf::initialise called twice");
  first_factor_of_pose_.push_back(0);
  state_.addPose(mean);
  Factor f{Factor::Kind::Prior, 0, -1, mean, covariance.inverse(), 0, nullptr, mean, Vec3::Zero()};
  addFactor(std::move(f));
  return 0;
}

void Esdf::pushChain(int k, int from, const Mat3& f_x, const Mat3& q) {
  if (!chain_valid_) return;
  const bool extends = from == k - 1 && from >= chain_base_;
  const bool lineage = from < chain_base_ && (from == chain_base_ - 1 || root_columns_.size() + 1 < kMaxLineages);
  if (k < chain_base_ || static_cast<size_t>(k - chain_base_) != chain_phi_.size() || !(extends || lineage)) {
    chain_valid_ = false;
    return;
  }
  if (lineage) {
    chain_phi_.push_back(f_x);
    chain_cov_.push_back(q);
    chain_root_.push_back(from);
    chain_lineage_.push_back(k);
    if (from != chain_base_ - 1) root_columns_.emplace(from, Eigen::MatrixXd());
  } else {
    const Mat3 phi = chain_phi_.back();
    const Mat3 cov = chain_cov_.back();
    chain_phi_.push_back(f_x * phi);
    chain_cov_.push_back(f_x * cov * f_x.transpose() + q);
    chain_root_.push_back(chain_root_.back());
    chain_lineage_.push_back(chain_lineage_.back());
  }
}

const Eigen::MatrixXd& Esdf::rootColumns(int r) {
  if (r == chain_base_ - 1) {
    if (base_columns_.size() == 0) covarianceColumnsBlock(r, &base_columns_);
    return base_columns_;
  }
  Eigen::MatrixXd& c = root_columns_[r];
  if (c.size() == 0) covarianceColumnsBlock(r, &c);
  return c;
}

int Esdf::predictAugment(std::shared_ptr<const MotionModel> model, const VecU& u, const MatQ& q_v, double dt_s) {
  if (state_.size() == 0) throw std::logic_error("Esdf: predict before initialise");
  const int dim = model->inputDimension();
  if (u.size() != dim || q_v.rows() != dim || q_v.cols() != dim)
    throw std::invalid_argument("predictAugment: u/Q_v size does not match the model");
  const int from = currentPose();
  Factor f;
  f.kind = Factor::Kind::Motion;
  f.a = from;
  f.z.setZero();
  f.z.head(dim) = u;
  f.weight.setZero();
  f.weight.topLeftCorner(dim, dim) = q_v;
  f.dt = dt_s;
  f.model = std::move(model);
  f.lin_a = state_.mean(from);
  f.lin_b = f.model->predict(f.lin_a, u, dt_s, nullptr, nullptr);
  first_factor_of_pose_.push_back(static_cast<int>(factors_.size()));
  f.b = state_.addPose(f.lin_b);
  // Dead-reckoning propagation for conservative covariances: x_b = F x_a + w, Cov w = Q.
  Mat3 fx;
  MatU fu;
  f.model->predict(f.lin_a, u, dt_s, &fx, &fu);
  pushChain(f.b, from, fx, processCovariance(fu, q_v, stabilisingNoise(*f.model)));
  const int k = f.b;
  addFactor(std::move(f));
  return k;
}

int Esdf::augmentRelative(int from, const Vec3& z, const Mat3& omega, bool measured_from_new) {
  if (state_.size() == 0) throw std::logic_error("Esdf: augment before initialise");
  if (from < 0 || from >= size()) throw std::out_of_range("augmentRelative: bad pose index");
  const Vec3 x_from = state_.mean(from);
  const Vec3 x_new = compose(x_from, measured_from_new ? inverse(z) : z);
  first_factor_of_pose_.push_back(static_cast<int>(factors_.size()));
  const int k = state_.addPose(x_new);
  Factor f{Factor::Kind::Relative, from, k, z, omega, 0, nullptr, x_from, x_new};
  if (measured_from_new) {
    std::swap(f.a, f.b);
    std::swap(f.lin_a, f.lin_b);
  }
  // x_new = -A_new^-1 A_from x_from + A_new^-1 v from the linearised edge error
  // A_from dx_from + A_new dx_new = v (for the conservative-covariance dead reckoning).
  const Linearisation l = linearise(f, f.lin_a, f.lin_b);
  const Mat3& a_from = measured_from_new ? l.a_b : l.a_a;
  const Mat3& a_new = measured_from_new ? l.a_a : l.a_b;
  const Mat3 an_inv = a_new.inverse();
  pushChain(k, from, -an_inv * a_from, an_inv * l.w.inverse() * an_inv.transpose());
  addFactor(std::move(f));
  return k;
}

void Esdf::predict(std::shared_ptr<const MotionModel> model, const VecU& u, const MatQ& q_v, double dt_s) {
  const int old = currentPose();
  predictAugment(std::move(model), u, q_v, dt_s);
  // Factors on the old pose are absorbed into the marginal and can no longer be relinearised.
  const int scan_from = first_factor_of_pose_[old];
  size_t out = static_cast<size_t>(scan_from);
  for (size_t f = static_cast<size_t>(scan_from); f < factors_.size(); ++f) {
    if (factors_[f].a == old || factors_[f].b == old) continue;
    factors_[out++] = std::move(factors_[f]);
  }
  factors_.resize(out);
  for (size_t f = static_cast<size_t>(scan_from); f < factors_.size(); ++f) {
    if (factors_[f].a > old) --factors_[f].a;
    if (factors_[f].b > old) --factors_[f].b;
  }
  state_.marginalise(old);
  first_factor_of_pose_.pop_back();  // the new pose takes the old one's slot and scan start
  chain_valid_ = false;
  full_factor_values_ = ~std::uint64_t{0};
  factors_of_pose_.clear();  // factors and poses renumbered: indexed again when asked
  factors_indexed_ = 0;
  markChanged();
}

ObservationResult Esdf::observeRelative(int i, int j, const Vec3& z, const Mat3& omega, bool gate) {
  if (i < 0 || j < 0 || i >= size() || j >= size() || i == j) throw std::out_of_range("observeRelative: bad pose indices");
  Factor f{Factor::Kind::Relative, i, j, z, omega, 0, nullptr, state_.mean(i), state_.mean(j)};
  if (options_.commit_heading_branch) {
    // The branch nearest the estimate: the heading difference the wrapped error points to.
    const double d = state_.mean(j).z() - state_.mean(i).z();
    f.z.z() = d - common::wrapToPi(d - z.z());
  }
  const Linearisation l = linearise(f, f.lin_a, f.lin_b);
  ObservationResult r;
  r.chi2 = l.e0.dot(omega * l.e0);
  if (gate) {
    r.gate = gateRelative(i, j, z, omega);
    r.accepted = r.gate.accepted;
    if (!r.accepted) return r;
  }
  addFactor(std::move(f));
  return r;
}

GateResult Esdf::gateRelative(int i, int j, const Vec3& z, const Mat3& omega) { return *gate(i, j, z, omega, false); }

std::optional<GateResult> Esdf::refusalWithoutFactorising(int i, int j, const Vec3& z, const Mat3& omega) {
  const std::optional<GateResult> r = gate(i, j, z, omega, true);
  if (r && !r->accepted) return r;
  return std::nullopt;
}

std::optional<GateResult> Esdf::gate(int i, int j, const Vec3& z, const Mat3& omega, bool without_factorising) {
  if (i < 0 || j < 0 || i >= size() || j >= size() || i == j) throw std::out_of_range("gateRelative: bad pose indices");
  const Vec3 e0 = relativePoseError(state_.mean(i), state_.mean(j), z);
  // S = H Sigma H' + R >= R, so d^2 = e' S^-1 e <= e' Omega e: a closure within the gate by
  // this bound is accepted without recovering any covariance (the common, consistent case).
  const double bound = e0.dot(omega * e0);
  if (bound <= single_gate_threshold_) {
    GateResult r;
    r.accepted = true;
    r.mahalanobis2 = bound;
    r.threshold = single_gate_threshold_;
    r.covariance_used = false;
    return r;
  }
  // e = ⊖z ⊕ r with r = ⊖x_i ⊕ x_j, so H Sigma H' = G Cov(r) G' with G = J2⊕(⊖z, r).
  Mat3 g;
  composeJacobians(inverse(z), Vec3::Zero(), nullptr, &g);
  const auto test = [&](const Mat3& rel) {
    // S = G Cov(r) G' + R with the innovation -e0 (the measurement "e = 0").
    return mahalanobisGateAt(-e0, g * rel * g.transpose() + omega.inverse(), single_gate_threshold_);
  };
  // The conservative covariance bounds the exact one from above, so its d^2 bounds the exact d^2
  // from below: a closure it refuses, the exact test refuses too. Only the closures it admits
  // need the exact covariance, which refactorises the whole map when the factor is stale (with a
  // current factor the exact covariance is solves with it, and the bound is skipped).
  const bool bound_only = options_.gate_covariance == CovarianceMode::Conservative;
  if (bound_only || (!factorCurrent() && conservativeReady())) {
    const GateResult r = test(relativeCovariance(i, j, CovarianceMode::Conservative));
    if (bound_only || !r.accepted) return r;
  }
  if (without_factorising) {
    // The exact covariance without a factorisation: the last one corrected by what came since
    // (ExactUpdates.cpp), as the exact gate would take it.
    Mat6 joint;
    if (factorCurrent() || !updatedJoint(i, j, &joint)) return std::nullopt;
    return test(betweenCovariance(state_.mean(i), state_.mean(j), joint));
  }
  return test(relativeCovariance(i, j, CovarianceMode::Exact));
}

bool Esdf::factorCurrent() const {
  return full_factor_.valid() && full_factor_values_ == values_stamp_ && full_factor_.last() == size() &&
         full_factor_.structureStamp() == state_.structureStamp();
}

void Esdf::ensureFactor() {
  if (factorCurrent()) return;
  // Lambda only gained information since the last factorisation (factors added, none changed):
  // the marginals of that one's poses still bound the new ones from above (kept when dear to
  // compute again; see factoredMarginal).
  const bool keep = full_factor_.valid() && explained_stamp_ == values_stamp_ && marginals_work_ >= options_.keep_marginals_min_work;
  full_factor_.factorize(state_, 0, size());
  ++factorisations_;
  full_factor_values_ = values_stamp_;
  factors_at_factor_ = factors_.size();
  explained_stamp_ = values_stamp_;
  involved_.clear();
  involved_paths_.clear();
  involved_at_.clear();
  involved_cov_.resize(0, 0);
  // A new reference for conservative covariances: chain restarts after the factored poses.
  chain_base_ = size();
  chain_phi_.clear();
  chain_cov_.clear();
  chain_root_.clear();
  chain_lineage_.clear();
  chain_valid_ = true;
  base_columns_.resize(0, 0);
  root_columns_.clear();
  newFactor(keep);
  anchor_base_ = -1;  // the anchor is looked for again in the new chain
  anchor_paths_from_ = -1;
}

RecoveryStats Esdf::recover(int max_passes, double cost_tolerance) {
  common::Stopwatch sw;
  RecoveryStats st;
  if (max_passes < 0) max_passes = options_.relinearise_max_passes;
  if (cost_tolerance < 0) cost_tolerance = options_.relinearise_cost_tolerance;
  const int n = size();
  Eigen::VectorXd old(3 * n);
  double c_known = -1;  // cost at the current mean, once known (relinearising leaves the mean)
  for (int pass = 0;; ++pass) {
    ensureFactor();
    const Eigen::VectorXd mu = full_factor_.solve(state_.denseEta());
    if (!options_.relinearise) {
      // The thesis filter: the mean is whatever the (once-linearised) information says.
      for (int p = 0; p < n; ++p) state_.setMean(p, mu.segment<3>(3 * p));
      break;
    }
    // Gauss-Newton with backtracking: a full step on a badly conditioned or strongly nonlinear
    // graph can increase the cost (and oscillate); halve it until the cost does not increase.
    for (int p = 0; p < n; ++p) old.segment<3>(3 * p) = state_.mean(p);
    const double c_old = c_known >= 0 ? c_known : cost();
    double alpha = 1.0, c_new = 0;
    for (;;) {
      for (int p = 0; p < n; ++p) state_.setMean(p, old.segment<3>(3 * p) + alpha * (mu.segment<3>(3 * p) - old.segment<3>(3 * p)));
      c_new = cost();
      if (c_new <= c_old * (1 + 1e-12) || alpha < 1.0 / 256) break;
      alpha *= 0.5;
      ++st.step_halvings;
    }
    if (c_new > c_old * (1 + 1e-12))
      for (int p = 0; p < n; ++p) state_.setMean(p, old.segment<3>(3 * p));
    c_known = c_new > c_old * (1 + 1e-12) ? c_old : c_new;
    if (pass > 0 && c_old - c_known <= cost_tolerance * c_old) {
      st.converged = true;  // a relinearised step that no longer pays
      break;
    }
    if (pass >= max_passes) break;
    const long long moved = relineariseMoved();
    if (moved == 0) {
      st.converged = true;
      break;
    }
    st.relinearise_passes = pass + 1;
    st.factors_relinearised += moved;
  }
  st.seconds = sw.seconds();
  return st;
}

Vec3 Esdf::factorError(const Factor& f, Mat3* w) const {
  const Vec3& xa = state_.mean(f.a);
  switch (f.kind) {
    case Factor::Kind::Prior:
      *w = f.weight;
      return poseDifference(xa, f.z);
    case Factor::Kind::Motion: {
      // The weight Q^-1 is the one of the factor's linearisation (it depends on F_u there).
      const int dim = f.model->inputDimension();
      Mat3 fx;
      MatU fu;
      f.model->predict(f.lin_a, f.z.head(dim), f.dt, &fx, &fu);
      *w = processInformation(fu, f.weight.topLeftCorner(dim, dim), stabilisingNoise(*f.model));
      return poseDifference(state_.mean(f.b), f.model->predict(xa, f.z.head(dim), f.dt, nullptr, nullptr));
    }
    case Factor::Kind::Relative:
      *w = f.weight;
      return relativeError(f, xa, state_.mean(f.b), nullptr, nullptr);
  }
  return Vec3::Zero();
}

double Esdf::cost() const {
  double c = 0;
  Mat3 w;
  for (const Factor& f : factors_) {
    const Vec3 e = factorError(f, &w);
    c += e.dot(w * e);
  }
  return c;
}

long long Esdf::relinearise() { return options_.relinearise ? relineariseMoved() : 0; }

long long Esdf::relineariseMoved() {
  const double tm = options_.relinearise_threshold_m, tr = options_.relinearise_threshold_rad;
  auto moved = [&](int p, const Vec3& lin) {
    const Vec3 d = state_.mean(p) - lin;
    return d.head<2>().norm() > tm || std::fabs(d.z()) > tr;
  };
  long long count = 0;
  for (Factor& f : factors_) {
    if (!moved(f.a, f.lin_a) && (f.b < 0 || !moved(f.b, f.lin_b))) continue;
    // One update of Lambda and eta with the difference of the two linearisations.
    Contribution c = contribution(f);
    c.scale(-1.0);
    f.lin_a = state_.mean(f.a);
    if (f.b >= 0) f.lin_b = state_.mean(f.b);
    c.accumulate(contribution(f));
    add(f, c);
    ++count;
  }
  return count;
}

void Esdf::recoverRecent(int first) {
  const int n = size();
  if (first <= 0) first = 0;
  if (first >= n) return;
  // Lambda_RR mu_R = eta_R - Lambda_RO mu_O, with O the poses before `first`.
  Eigen::VectorXd rhs(3 * (n - first));
  for (int p = first; p < n; ++p) {
    Vec3 r = state_.eta(p);
    for (const auto& l : state_.links(p))
      if (l.other < first) r -= l.block * state_.mean(l.other);
    rhs.segment<3>(3 * (p - first)) = r;
  }
  window_factor_.factorize(state_, first, n);
  const Eigen::VectorXd mu = window_factor_.solve(rhs);
  for (int p = first; p < n; ++p) state_.setMean(p, mu.segment<3>(3 * (p - first)));
}

Mat3 Esdf::covarianceColumnsBlock(int i, Eigen::MatrixXd* columns) {
  const int n = full_factor_.last();
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(3 * n, 3);
  e.block<3, 3>(3 * i, 0).setIdentity();
  *columns = full_factor_.solve(e);
  return columns->block<3, 3>(3 * i, 0);
}

Mat3 Esdf::marginalCovariance(int i, CovarianceMode mode) { return jointCovariance(i, i, mode).topLeftCorner<3, 3>(); }

bool Esdf::conservativeReady() const {
  return full_factor_.valid() && chain_valid_ && full_factor_.last() == chain_base_ && chain_base_ > 0 && full_factor_.first() == 0 &&
         static_cast<int>(chain_phi_.size()) == size() - chain_base_;
}

Mat3 Esdf::relativeCovariance(int i, int j, CovarianceMode mode) {
  if (i < 0 || j < 0 || i >= size() || j >= size() || i == j) throw std::out_of_range("relativeCovariance: bad poses");
  if (mode == CovarianceMode::Conservative && conservativeReady()) {
    Mat3 r;
    conservativeJoint(i, j, &r);
    return r;
  }
  return betweenCovariance(state_.mean(i), state_.mean(j), jointCovariance(i, j, mode));
}

Mat6 Esdf::jointCovariance(int i, int j, CovarianceMode mode) {
  if (i < 0 || j < 0 || i >= size() || j >= size()) throw std::out_of_range("jointCovariance: bad pose");
  if (mode == CovarianceMode::Conservative && conservativeReady()) return conservativeJoint(i, j, nullptr);
  if (Mat6 s; !factorCurrent() && updatedJoint(i, j, &s)) return s;
  ensureFactor();
  const int n = size();
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(3 * n, 6);
  e.block<3, 3>(3 * i, 0).setIdentity();
  e.block<3, 3>(3 * j, 3) += Mat3::Identity();
  if (i == j) e.block<3, 3>(3 * j, 3).setIdentity();
  const Eigen::MatrixXd x = full_factor_.solve(e);
  Mat6 s;
  s << x.block<3, 3>(3 * i, 0), x.block<3, 3>(3 * i, 3), x.block<3, 3>(3 * j, 0), x.block<3, 3>(3 * j, 3);
  return 0.5 * (s + s.transpose());
}

Mat3 Esdf::chainedCovariance(int p, int q) {
  if (p > q) return chainedCovariance(q, p).transpose();
  const int m = chain_base_;
  if (q < m) return involved_cov_.block<3, 3>(3 * involved_at_.at(p), 3 * involved_at_.at(q));
  // x_q = Phi_q x_r + n_q, with n_q independent of the factored poses.
  const size_t iq = static_cast<size_t>(q - m);
  const Mat3& phi_q = chain_phi_[iq];
  const int r_q = chain_root_[iq];
  if (p < m) return rootColumns(r_q).block<3, 3>(3 * p, 0) * phi_q.transpose();
  const size_t ip = static_cast<size_t>(p - m);
  const Mat3& phi_p = chain_phi_[ip];
  const int r_p = chain_root_[ip];
  // Two lineages: independent noises, the roots' covariance between them.
  if (chain_lineage_[ip] != chain_lineage_[iq]) return phi_p * rootColumns(r_q).block<3, 3>(3 * r_p, 0) * phi_q.transpose();
  const Mat3 spp = phi_p * rootColumns(r_p).block<3, 3>(3 * r_p, 0) * phi_p.transpose() + chain_cov_[ip];
  if (p == q) return spp;
  // x_q = Phi_q Phi_p^-1 x_p + noise of the links after p.
  return spp * (phi_q * phi_p.inverse()).transpose();
}

Mat6 Esdf::conservativeJoint(int i, int j, Mat3* relative) {
  // The last factorisation is of an older Lambda, which holds less information than the current
  // one (if no relinearisation happened since): its inverse bounds the current covariance from
  // above. Poses added after it are reached by dead reckoning from the last factored pose m-1.
  const int m = chain_base_;
  auto chainPhi = [&](int p) -> const Mat3& { return chain_phi_[static_cast<size_t>(p - m)]; };
  auto marginal = [&](int p) -> Mat3 {
    if (p >= m) return chainedCovariance(p, p);
    return factoredMarginal(p);
  };
  auto cross = [&](int a, int b) -> Mat3 {  // Sigma(a, b) for a < b
    if (b < m) return SparseCholesky::covarianceBetween(full_factor_.pathSolve(a), full_factor_.pathSolve(b));
    return chainedCovariance(a, b);
  };
  const auto joint = [&](const Mat3& saa, const Mat3& sbb, const Mat3& sab) {
    Mat6 s;
    if (i <= j)
      s << saa, sab, sab.transpose(), sbb;
    else
      s << sbb, sab.transpose(), sab, saa;
    return Mat6(0.5 * (s + s.transpose()));
  };
  const int a = std::min(i, j), b = std::max(i, j);
  const Mat6 s = i == j ? joint(marginal(i), marginal(i), marginal(i)) : joint(marginal(a), marginal(b), cross(a, b));
  const auto spread = [](const Mat3& c) { return c(0, 0) + c(1, 1); };
  if (relative) *relative = betweenCovariance(state_.mean(i), state_.mean(j), s);
  // Through the newest closure into the chain, when it lies on the way to b (and a is factored or
  // b's own marginal is asked): both are upper bounds, and the one that bounds the marginal (or
  // the relative pose) tighter is returned.
  const ChainAnchor& an = chainAnchor();
  if (an.a < 0 || b < an.b || (a >= m && i != j)) return s;
  // The chain after the closure carries it to b only within the closure's lineage.
  if (chain_lineage_[static_cast<size_t>(b - m)] != chain_lineage_[static_cast<size_t>(an.b - m)]) return s;
  const Mat3 sa = marginal(an.a);
  const Mat3 step = chainPhi(b) * chainPhi(an.b).inverse();  // x_b from x_{an.b} by the chain
  const Mat3 to_b = step * an.phi;                           // d x_b / d x_{an.a}
  const Mat3 increments = chain_cov_[static_cast<size_t>(b - m)] - step * chain_cov_[static_cast<size_t>(an.b - m)] * step.transpose();
  const Mat3 sbb = to_b * sa * to_b.transpose() + step * an.cov * step.transpose() + increments;
  if (i == j) return spread(sbb) < spread(s.topLeftCorner<3, 3>()) ? joint(sbb, sbb, sbb) : s;
  // The pair: a from an.a by the factors alone on the path between them (anchorPath), then the
  // closure and the chain after it. That bounds their relative pose, not their joint (x_{an.a}
  // enters both as it is), so the joint stays s.
  const PathBound* path = relative ? anchorPath(a) : nullptr;
  if (!path) return s;
  const Mat3 t = betweenCovariance(state_.mean(i), state_.mean(j),
                                   joint(path->phi * sa * path->phi.transpose() + path->cov, sbb, path->phi * sa * to_b.transpose()));
  if (spread(t) < spread(*relative)) *relative = t;
  return s;
}

Mat3 Esdf::factoredMarginal(int p) {
  // While the vehicle drives along an earlier visit its keyframes are candidates one after
  // another: every factored pose's marginal at once, from the factor's sparse inverse, for about
  // the cost of one more factorisation. A factorisation that only added information since the
  // one the sparse inverse came from (the innovation gate's, between the full recoveries) keeps
  // it when a new one would be dear (EsdfOptions::keep_marginals_min_work): Lambda grew by
  // positive terms, so its marginals bound the new ones from above, as the conservative
  // covariance asks, if more loosely. On a map of 10^6 keyframes, where the fill of every pass
  // of a street makes a sparse inverse cost minutes, most factorisations are the gate's. The
  // poses it does not cover (factored since, near the vehicle) come from path solves, each
  // costing its path in the factor, until their work reaches a new sparse inverse's: never more
  // than twice the cheaper.
  if (static_cast<size_t>(p) < factored_marginals_.size()) return factored_marginals_[static_cast<size_t>(p)];
  if (const auto it = path_marginals_.find(p); it != path_marginals_.end()) return it->second;
  if (factored_marginals_.empty() || path_marginal_work_ >= inverseWork()) {
    factored_marginals_ = full_factor_.inverseDiagonalBlocks();
    marginals_work_ = inverseWork();
    path_marginals_.clear();
    return factored_marginals_[static_cast<size_t>(p)];
  }
  const PathSolution y = full_factor_.pathSolve(p);
  path_marginal_work_ += y.work;
  const Mat3 s = SparseCholesky::covarianceBetween(y, y);
  return path_marginals_[p] = 0.5 * (s + s.transpose());
}

double Esdf::inverseWork() {
  if (inverse_work_ < 0) inverse_work_ = full_factor_.inverseWork();
  return inverse_work_;
}

double Esdf::recoveryWork() {
  if (!full_factor_.valid()) return 0;
  if (factorisation_work_ < 0) factorisation_work_ = full_factor_.factorisationWork();
  return factorisation_work_ + inverseWork();
}

void Esdf::newFactor(bool keep_marginals) {
  if (!keep_marginals) {
    factored_marginals_.clear();
    marginals_work_ = 0;
  }
  path_marginals_.clear();
  path_marginal_work_ = 0;
  inverse_work_ = factorisation_work_ = -1;
}

const Esdf::ChainAnchor& Esdf::chainAnchor() {
  if (anchor_factors_ == factors_.size() && anchor_base_ == chain_base_) return anchor_;
  anchor_factors_ = factors_.size();
  anchor_base_ = chain_base_;
  anchor_ = {};
  const int m = chain_base_;
  // Every factor that touches a chain pose was added after the factorisation: newest first, back
  // to the first that does not.
  for (size_t k = factors_.size(); k-- > 0;) {
    const Factor& f = factors_[k];
    if (std::max(f.a, f.b) < m) break;
    // (A chain pose's first factor is its own link: from its predecessor or its lineage's root.)
    if (f.kind != Factor::Kind::Relative || f.a >= m || f.b < m || first_factor_of_pose_[static_cast<size_t>(f.b)] == static_cast<int>(k))
      continue;
    Mat3 d_a, d_e;
    factorStep(f, true, &d_a, &d_e);
    anchor_.a = f.a;
    anchor_.b = f.b;
    anchor_.phi = d_a;
    anchor_.cov = d_e * f.weight.inverse() * d_e.transpose();
    break;
  }
  return anchor_;
}

size_t Esdf::memoryBytes() const {
  // (The factors grow by fixed blocks: their size is their memory, to a block.)
  return state_.memoryBytes() + factors_.size() * sizeof(Factor) + first_factor_of_pose_.capacity() * sizeof(int) +
         (chain_phi_.capacity() + chain_cov_.capacity()) * sizeof(Mat3) + (chain_root_.capacity() + chain_lineage_.capacity()) * sizeof(int) +
         static_cast<size_t>(involved_cov_.size()) * sizeof(double);
}

}  // namespace urbanslam::esdf
