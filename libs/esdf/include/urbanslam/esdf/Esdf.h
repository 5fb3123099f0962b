#pragma once
// The Exactly Sparse Delayed-state Filter (Eustice, Singh & Leonard; thesis chapter 2) over 2D
// poses, in information form.
//
// * Prediction with augmentation adds the new pose and a link to the current one only: O(1).
// * Prediction without augmentation marginalises the previous current pose (Schur complement on
//   its neighbours), which is how a plain EKF-style filter would keep a single vehicle pose.
// * An observation of the relative pose between any two poses adds information to their two
//   block rows only, after an optional Mahalanobis gate.
// * The mean is not maintained by the information form itself: recover() solves
//   Lambda mu = eta with CHOLMOD; recoverRecent() solves for a window of recent poses with the
//   older ones held fixed. Covariances of selected poses (and pairs) come from solves with the
//   last factor (path solves for pairs between factorisations, PathSolve.h).
//
// Beyond the thesis: every measurement is kept as a factor with its linearisation point, so
// after a recovery the factors whose poses moved are re-linearised (their old contribution to
// Lambda and eta is subtracted and a new one added) and the system re-solved. With it the
// filter reaches the batch (Gauss-Newton) optimum after a large loop closure instead of keeping
// the first linearisation's error.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <queue>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "urbanslam/esdf/EnvelopeCholesky.h"
#include "urbanslam/esdf/Gating.h"
#include "urbanslam/esdf/InformationState.h"
#include "urbanslam/esdf/MotionModels.h"
#include "urbanslam/esdf/Recovery.h"

namespace urbanslam::esdf {

using Mat6 = Eigen::Matrix<double, 6, 6>;

enum class CovarianceMode {
  Exact,        // the current Lambda's: from the last factor and the few factors added since
                // (ExactUpdates.cpp), else refactorised; then solves with the factor
  Conservative  // last factorisation + dead-reckoning propagation: no refactorisation, never smaller
};

struct EsdfOptions {
  // Diagonal of the stabilising noise Q_s (eq. 2.21) for the two-input vehicle models; as small
  // as possible (thesis 2.2.4) while keeping Q invertible.
  double stabilising_noise_xy_m2 = 1e-6;
  double stabilising_noise_phi_rad2 = 1e-8;

  // Innovation gate: the chi-square quantile probability (3 dof) for relative-pose observations.
  double chi2_gate_probability = 0.999;
  // Exact: the exact test's decision, with the conservative bound refusing first what it can (no
  // refactorisation); Conservative: the bound alone (admits more).
  CovarianceMode gate_covariance = CovarianceMode::Exact;

  // Relinearisation after a full recovery: factors whose poses moved more than these thresholds
  // since their linearisation are re-linearised, then the system is re-solved, up to
  // relinearise_max_passes times.
  bool relinearise = true;
  double relinearise_threshold_m = 1e-3;
  double relinearise_threshold_rad = 1e-4;
  int relinearise_max_passes = 20;
  // ...or until a relinearised Gauss-Newton step lowers cost() by less than this fraction (the
  // function tolerance of batch solvers; the pose-graph back end uses Ceres's default 1e-6).
  // 0: stop when nothing moves past the thresholds or a relinearised step gains nothing.
  double relinearise_cost_tolerance = 0;

  FillReducingOrdering ordering = FillReducingOrdering::Amd;
  // With AMD: a whole-map factorisation AMD's ordering makes this dear (floating-point
  // operations, CHOLMOD's count) is ordered by METIS's nested dissection too, the cheaper one
  // used (SparseCholesky). 5·10^10 is several seconds of factorisation, where METIS's analysis
  // costs a fraction of one; at 10^6 keyframes of a city driven many times nested dissection's
  // factor has a quarter fewer non-zeros and a third of AMD's operations. 0: AMD alone.
  double nested_dissection_min_flops = 5e10;

  // A factorisation that only added information to the one the factored poses' marginals came
  // from keeps them (upper bounds, CovarianceMode::Conservative) when computing them again would
  // take at least this many multiply-adds (a sparse inverse: 10^10 is seconds, 10^6 keyframes of
  // a city take 2.5·10^11); below, they are computed again, tighter.
  double keep_marginals_min_work = 1e10;

  // A relative-pose factor keeps the heading branch it was linearised on when added (the one
  // nearest the estimate then): its heading error is never re-wrapped. Re-wrapping at each
  // relinearisation lets a stale estimate flip an earlier closure onto the other branch, and
  // it makes the heading part of the problem piecewise rather than linear, which
  // reinitialiseFromHeadings() relies on.
  bool commit_heading_branch = false;
};

struct ObservationResult {
  bool accepted = true;
  GateResult gate;  // filled when the observation was gated
  double chi2 = 0;  // e' Omega e of the innovation at the linearisation point
};

struct RecoveryStats {
  int relinearise_passes = 0;
  long long factors_relinearised = 0;
  bool converged = false;  // nothing left to relinearise, or the cost tolerance was reached
  int step_halvings = 0;   // backtracking steps taken (see recover())
  double seconds = 0;
};

class Esdf {
 public:
  explicit Esdf(EsdfOptions options = {});
  ~Esdf();

  const EsdfOptions& options() const { return options_; }
  void reserve(int poses);

  // Starts the trajectory: pose 0 with a Gaussian prior (mean, covariance).
  int initialise(const Vec3& mean, const Mat3& covariance);

  // Prediction with augmentation from the current (last) pose with a motion model: adds a pose
  // with mean f(x_v, u) and returns its index. The filter keeps `model` for relinearisation.
  int predictAugment(std::shared_ptr<const MotionModel> model, const VecU& u, const MatQ& q_v, double dt_s);
  // Prediction without augmentation: the current pose is replaced by its prediction (augment,
  // then marginalise the old current pose). The marginalised information stays linearised.
  void predict(std::shared_ptr<const MotionModel> model, const VecU& u, const MatQ& q_v, double dt_s);
  // Prediction with augmentation from any earlier pose `from` by a relative pose z with
  // information omega (the laser/odometry model x ⊕ u with Q = J2⊕ Omega^-1 J2⊕'), using the
  // g2o edge error so that pose-graph chi2 is minimised exactly.
  // With measured_from_new, z is the pose of `from` seen from the new pose (an edge new -> from,
  // as pose-graph files sometimes store odometry); the edge is kept as given, not inverted.
  int augmentRelative(int from, const Vec3& z, const Mat3& omega, bool measured_from_new = false);

  // Relative-pose observation z = ⊖x_i ⊕ x_j (+ noise with information omega), linearised at the
  // current mean. When `gate` is true, it is first tested against the chi2 gate with the joint
  // covariance of (x_i, x_j) (options().gate_covariance) and discarded when inconsistent.
  ObservationResult observeRelative(int i, int j, const Vec3& z, const Mat3& omega, bool gate = false);
  // The gate test alone (nothing is added): d^2 of the innovation at the current mean.
  GateResult gateRelative(int i, int j, const Vec3& z, const Mat3& omega);
  // The gate's refusal when it is known without a factorisation (by the conservative covariance,
  // or by the exact one from the last factorisation and the closures since, ExactUpdates.cpp):
  // gateRelative then refuses z too, with this result. Nothing when the gate may admit z or only
  // a factorisation could tell. For a caller with costly checks of its own to skip when the gate
  // will refuse anyway.
  std::optional<GateResult> refusalWithoutFactorising(int i, int j, const Vec3& z, const Mat3& omega);
  // The joint gate of two relative-pose observations (JointGate.cpp): d^2 of their stacked
  // innovations with the exact 6x6 covariance (the poses' cross-covariances included) against
  // jointGateThreshold(). Nothing is added; between factorisations no factorisation either.
  GateResult gateRelativePair(int i1, int j1, const Vec3& z1, const Mat3& omega1, int i2, int j2, const Vec3& z2, const Mat3& omega2);
  // The 6-dof quantile of chi2_gate_probability: what two closures gated jointly may reach, and
  // so what no single closure beyond it can pass with a second one.
  double jointGateThreshold() const { return joint_gate_threshold_; }
  // The 3-dof quantile of chi2_gate_probability: a single closure's gate.
  double gateThreshold() const { return single_gate_threshold_; }
  // The exact joint covariance of `poses` (3k x 3k, in the order given): from the last factor and
  // the closures since when it can (updatedCovariance), else path solves of a current factor.
  Eigen::MatrixXd covarianceAmong(const std::vector<int>& poses);

  // Full recovery: factorise Lambda (CHOLMOD), mu = Lambda^-1 eta, then (if enabled) up to
  // max_relinearise_passes rounds of relinearise + re-solve (-1: options().relinearise_max_passes).
  // With relinearisation each solve is a Gauss-Newton step from the current mean, shortened
  // (halved) while it would increase cost().
  // `cost_tolerance` >= 0 replaces options().relinearise_cost_tolerance for this recovery.
  RecoveryStats recover(int max_relinearise_passes = -1, double cost_tolerance = -1);
  // Relinearises the factors whose poses moved past the thresholds since their linearisation
  // (Lambda and eta updated exactly); returns how many. The mean is left as it is.
  long long relinearise();
  // Partial recovery of poses [first, size()) with the older poses held at their current mean.
  void recoverRecent(int first);
  // A new linearisation point from the headings first (as LAGO does, Carlone et al. 2014): the
  // headings that minimise the heading errors alone (a linear problem once every factor has a
  // branch: commit_heading_branch), then the positions that minimise the whole cost with those
  // headings held (linear too), then every factor relinearised there. No Gauss-Newton step of
  // the whole problem can undo a 2*pi twist that a stale estimate puts into a long loop; the
  // headings-first solution has none, and it costs two sparse solves smaller than Lambda's.
  // Returns the number of factors relinearised. Prior and relative-pose factors only
  // (std::logic_error with motion-model factors); it solves from the kept factors, so a filter
  // that marginalised poses (predict()) loses their information here.
  long long reinitialiseFromHeadings();

  // Marginal covariance of pose i and joint covariance of (x_i, x_j) (6x6, i's block first).
  Mat3 marginalCovariance(int i, CovarianceMode mode = CovarianceMode::Exact);
  Mat6 jointCovariance(int i, int j, CovarianceMode mode = CovarianceMode::Exact);
  // Covariance of the relative pose ⊖x_i ⊕ x_j (i != j). Conservative: also through the newest
  // closure into the dead-reckoned poses and the factors alone on the path from its earlier end
  // to the older pose (a bound on the relative pose only, with no solve over the map).
  Mat3 relativeCovariance(int i, int j, CovarianceMode mode = CovarianceMode::Exact);

  // A bound on the covariance of ⊖x_i ⊕ x_j (i != j) from the relative factors alone on the
  // tightest path between them (a subset of the factors holds less information), found within
  // `max_poses` settled poses and kAnchorPathLinks links: no solve over the map, for poses a few
  // factors apart. False when no path reached the other pose. The search starts from j (or from i
  // when the last one did) and is resumed by the next query from the same pose while the filter
  // does not change: the candidates of one keyframe are one search.
  bool pathRelativeCovariance(int i, int j, Mat3* cov, size_t max_poses = kAnchorPathPoses);

  int size() const { return state_.size(); }
  int currentPose() const { return state_.size() - 1; }
  const Vec3& mean(int i) const { return state_.mean(i); }
  const InformationState& state() const { return state_; }
  size_t factorCount() const { return factors_.size(); }
  long long factorNonZeros() const { return full_factor_.factorNonZeros(); }
  // What a full recovery will cost, in multiply-adds, estimated from the last factor: a
  // factorisation and the sparse inverse the candidates' covariances then take (0 without one;
  // counted once per factorisation).
  double recoveryWork();
  size_t memoryBytes() const;
  // Factorisations of the whole map by this object (recoveries, exact covariances): what grows
  // with the map. A count of this process's work, not saved with the filter's state.
  long long factorisations() const { return factorisations_; }

  // Total cost sum e' W e of the kept factors at the current mean (marginalised information
  // excluded): what relinearisation minimises.
  double cost() const;

  // Re-linearises every factor whose poses moved beyond the thresholds; returns their number.
  // recover() calls it; exposed for tests and experiments.
  long long relineariseMoved();

  // The filter's whole state, so that a filter read back continues exactly as this one would
  // (EsdfState.cpp): the information form, the factors with their linearisation points, the
  // matrix of the last full factorisation (refactorised on reading: conservative covariances
  // come from it) and the dead-reckoning chain. The options are not written: the reader is
  // constructed with the options of the writer. Filters holding motion-model factors
  // (predictAugment) cannot be written (std::logic_error): a model is code, not data.
  void writeState(common::BinaryWriter& w) const;
  // Into a filter with no poses yet. Throws common::InputError (naming the reader's file) for
  // inconsistent contents. `with_updates`: the state records which factors came after the last
  // factorisation (written since map format 9; older states refactorise at the next exact query).
  // `with_lineages`: the chain's poses record the factored pose each descends from (written since
  // map format 10; older chains all descend from the last factored pose).
  void readState(common::BinaryReader& r, bool with_updates = true, bool with_lineages = true);

 private:
  struct Factor {
    enum class Kind : std::uint8_t { Prior, Motion, Relative };
    Kind kind;
    int a, b;     // b = -1 for a prior
    Vec3 z;       // prior mean, motion input u (padded), or relative measurement
    Mat3 weight;  // prior information, Q_v (padded), or Omega
    double dt = 0;
    std::shared_ptr<const MotionModel> model;
    Vec3 lin_a, lin_b;  // linearisation point
  };
  struct Linearisation {
    Mat3 a_a, a_b, w;
    Vec3 e0;
  };
  Linearisation linearise(const Factor& f, const Vec3& xa, const Vec3& xb) const;
  // relativePoseError for a relative factor, on its committed branch when commit_heading_branch.
  Vec3 relativeError(const Factor& f, const Vec3& xa, const Vec3& xb, Mat3* ja, Mat3* jb) const;
  // Error of a factor at the current mean and its weight.
  Vec3 factorError(const Factor& f, Mat3* w) const;
  // A factor's contribution to Lambda (blocks aa, bb, ab) and eta at its linearisation point.
  struct Contribution {
    Mat3 aa = Mat3::Zero(), bb = Mat3::Zero(), ab = Mat3::Zero();
    Vec3 eta_a = Vec3::Zero(), eta_b = Vec3::Zero();
    void scale(double k) {
      aa *= k;
      bb *= k;
      ab *= k;
      eta_a *= k;
      eta_b *= k;
    }
    void accumulate(const Contribution& o) {
      aa += o.aa;
      bb += o.bb;
      ab += o.ab;
      eta_a += o.eta_a;
      eta_b += o.eta_b;
    }
  };
  Contribution contribution(const Factor& f) const;
  void add(const Factor& f, const Contribution& c);
  // Adds (sign = +1) or removes (sign = -1) a factor's contribution at its linearisation point.
  void apply(const Factor& f, double sign);
  void addFactor(Factor f);
  Vec3 stabilisingNoise(const MotionModel& m) const;
  // Dead-reckoning propagation for conservative covariances (see jointCovariance).
  void pushChain(int k, int from, const Mat3& f_x, const Mat3& q);
  // The full factor is of the current Lambda (nothing added or relinearised since).
  bool factorCurrent() const;
  void ensureFactor();
  Mat3 covarianceColumnsBlock(int i, Eigen::MatrixXd* columns);
  bool conservativeReady() const;
  // The conservative joint; with `relative` (i != j) also the tightest relative-pose bound.
  Mat6 conservativeJoint(int i, int j, Mat3* relative);
  // A second path from the factorisation into the chain: the newest relative factor from a
  // factored pose a to a chain pose b (a loop closure: x_b = x_a ⊕ z ⊕ noise). A chain pose at
  // or after b is reached from a through it and the chain's increments after b, which, while the
  // vehicle drives along an earlier visit, is far tighter than the dead reckoning from the
  // chain's base. a = -1: none.
  struct ChainAnchor {
    int a = -1, b = -1;
    Mat3 phi = Mat3::Identity();  // d x_b / d x_a
    Mat3 cov = Mat3::Zero();      // the closure's noise, mapped onto x_b
  };
  const ChainAnchor& chainAnchor();
  // A factored pose p as reached from the anchor's factored end a through the factors alone on
  // the path between them (AnchorPaths.cpp): x_p = phi x_a + w, Cov w = cov. The relative pose
  // of p and a chain pose through that path and the closure bounds the exact one (a subset of
  // the factors holds less information), with no solve over the map. nullptr: no path of at most
  // kAnchorPathLinks factors reached p before the search settled kAnchorPathPoses poses.
  struct PathBound {
    Mat3 phi = Mat3::Identity();
    Mat3 cov = Mat3::Zero();
  };
  static constexpr int kAnchorPathLinks = 64;
  static constexpr size_t kAnchorPathPoses = 4096;  // the path search settles at most this many poses
  const PathBound* anchorPath(int p);
  // gateRelative, stopping short of the exact covariance when without_factorising: nothing then
  // where only the exact covariance (a factorisation) could decide.
  std::optional<GateResult> gate(int i, int j, const Vec3& z, const Mat3& omega, bool without_factorising);
  // A relative factor from its end a (from_a) or b to the other: d_x the Jacobian of the other
  // pose in this one, d_e in the factor's noise (AnchorPaths.cpp).
  static void factorStep(const Factor& f, bool from_a, Mat3* d_x, Mat3* d_e);
  void indexFactors();
  void markChanged() { ++values_stamp_; }
  // The exact joint covariance of poses i and j without refactorising (ExactUpdates.cpp): the
  // last factor, the dead-reckoning chain after it, and the factors added since as a low-rank
  // update (Woodbury). False when Lambda changed otherwise since the factorisation, or the
  // update asks for more poses not solved for yet than ExactUpdates.cpp allows.
  bool updatedJoint(int i, int j, Mat6* joint);
  // The same for any few poses (3k x 3k, in the order given).
  bool updatedCovariance(const std::vector<int>& targets, Eigen::MatrixXd* cov);
  // Sigma(p, q) of the factorised Lambda with the chain after it: for a chain pose, the
  // conservative covariance's dead reckoning (exact while no closure came since); for two
  // factored poses, the blocks solveInvolved kept.
  Mat3 chainedCovariance(int p, int q);
  // Makes the blocks of Sigma among `poses` (factored) available: a path solve (PathSolve.h)
  // for each not solved for yet, its blocks with the others from the paths.
  void solveInvolved(const std::vector<int>& poses);

  EsdfOptions options_;
  InformationState state_;
  // Two or more per pose, up to millions: a deque grows by fixed blocks, where a vector's doubling
  // leaves up to half its capacity unused and holds three times its size while it moves.
  std::deque<Factor> factors_;
  std::vector<int> first_factor_of_pose_;  // factors_.size() when the pose was created

  SparseCholesky full_factor_;
  EnvelopeCholesky window_factor_;                     // partial recovery of the recent poses
  double joint_gate_threshold_;   // jointGateThreshold()
  double single_gate_threshold_;  // gateThreshold()
  // Two slots of the state's format that held the gate's quantile, cached at its first use; the
  // thresholds above come from the options now. Nothing reads them: they are carried as read, so
  // that a filter written again gives the same bytes.
  std::array<double, 2> unused_gate_slots_{-1, 0};
  std::uint64_t values_stamp_ = 0;                     // bumped on every change of Lambda or eta
  std::uint64_t full_factor_values_ = ~std::uint64_t{0};
  long long factorisations_ = 0;
  // Lambda = the factorised one + the chain's links + factors_[factors_at_factor_, end) while
  // values_stamp_ == explained_stamp_ (every change but addFactor leaves it behind).
  size_t factors_at_factor_ = 0;
  std::uint64_t explained_stamp_ = ~std::uint64_t{0};
  std::vector<int> involved_;               // factored poses whose Sigma blocks are known ...
  std::vector<PathSolution> involved_paths_;  // ... their path solves (PathSolve.h)
  std::unordered_map<int, int> involved_at_;  // ... their place in involved_
  Eigen::MatrixXd involved_cov_;            // ... the blocks among them (3|involved| square)

  // Conservative covariance support: for poses k >= chain_base_, x_k = Phi_k x_r + noise with
  // accumulated noise C_k, where r (chain_root_) is a factored pose: the chain descends from
  // the last factored pose base-1, and a pose added from another factored pose starts a lineage
  // of its own from that one (a keyframe added from an earlier one than the newest). Each
  // pose comes from its predecessor or from a factored pose; the noises of two lineages are
  // independent. chain_lineage_: the lineage's first pose.
  int chain_base_ = 0;
  std::vector<Mat3> chain_phi_, chain_cov_;
  std::vector<int> chain_root_, chain_lineage_;
  bool chain_valid_ = true;
  Eigen::MatrixXd base_columns_;          // stale Sigma(:, base-1), from the last full factorisation
  std::unordered_map<int, Eigen::MatrixXd> root_columns_;  // ... and Sigma(:, r) of the other lineages' roots
  static constexpr size_t kMaxLineages = 8;  // beyond, refactorising is cheaper than their column solves
  // Sigma(:, r) of the last full factorisation for a lineage's root r.
  const Eigen::MatrixXd& rootColumns(int r);
  // Sigma(p, p) of the factored poses from a sparse inverse, of this factorisation or of an
  // earlier one with less information (factoredMarginal); empty: not yet computed.
  std::vector<Mat3> factored_marginals_;
  // Poses beyond those: each from its path solve, while their work stays below a new sparse
  // inverse's.
  std::unordered_map<int, Mat3> path_marginals_;
  double path_marginal_work_ = 0;
  double marginals_work_ = 0;  // what the sparse inverse of factored_marginals_ took
  // The current factor's sparse inverse and numeric factorisation in multiply-adds, counted when
  // first needed (-1: not yet).
  double inverse_work_ = -1, factorisation_work_ = -1;
  double inverseWork();
  // Sigma(p, p) of factored pose p from the last factorisation.
  Mat3 factoredMarginal(int p);
  // A new factor (a factorisation or a load): what was computed from the last one dropped, but
  // with `keep_marginals` (only information added since) factored_marginals_.
  void newFactor(bool keep_marginals = false);
  ChainAnchor anchor_;
  size_t anchor_factors_ = 0;                        // factors_.size() when anchor_ was looked for ...
  int anchor_base_ = -1;                             // ... and chain_base_ then
  struct PathEntry {
    double spread;
    int pose, links;
    bool operator>(const PathEntry& o) const { return spread > o.spread; }
  };
  // A search for the tightest paths from one pose (Dijkstra on the accumulated position spread),
  // resumed as more poses are asked for.
  struct PathSearch {
    int from = -1;
    std::uint64_t stamp = 0;  // pathRelativeCovariance's: values_stamp_ when started
    std::unordered_map<int, PathBound> paths;
    std::unordered_set<int> settled;
    std::priority_queue<PathEntry, std::vector<PathEntry>, std::greater<PathEntry>> open;
    void start(int pose);
  };
  // Settles poses of `s` until `to` is settled, the search runs out or `max_poses` are settled,
  // over paths of at most kAnchorPathLinks factors through poses below `below`.
  void searchPaths(PathSearch& s, int to, size_t max_poses, int below);
  PathSearch anchor_search_;  // from anchor_paths_from_, within the factored poses
  int anchor_paths_from_ = -1, anchor_paths_base_ = -1;
  PathSearch path_search_;  // pathRelativeCovariance's, kept while values_stamp_ stays
  std::vector<std::vector<int>> factors_of_pose_;  // the factors touching each pose (anchorPath's graph) ...
  size_t factors_indexed_ = 0;                     // ... for factors_[0, this)
};

}  // namespace urbanslam::esdf
