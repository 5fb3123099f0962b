#include "urbanslam/alignment/CrfMatch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "urbanslam/alignment/Icp.h"

namespace urbanslam::alignment {

using common::Pose2;

std::vector<std::vector<double>> crfShapeFeatures(const SubsamplingResult& s,
                                                  const std::vector<double>& radii_m) {
  const int n = static_cast<int>(s.segmented.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<double>> f(n, std::vector<double>(radii_m.size(), nan));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = s.segmented[i].p;
    for (size_t k = 0; k < radii_m.size(); ++k) {
      const double r2 = radii_m[k] * radii_m[k];
      // The first points of the same segment at least r away on either side along the sweep:
      // the angle they make at p depends on the surface shape only, not on where it is seen
      // from (unlike index offsets, which depend on the beam density at that range).
      int b = i - 1;
      while (b >= 0 && s.segment[b] == s.segment[i] && (s.segmented[b].p - p).squaredNorm() < r2) --b;
      int e = i + 1;
      while (e < n && s.segment[e] == s.segment[i] && (s.segmented[e].p - p).squaredNorm() < r2) ++e;
      if (b < 0 || e >= n || s.segment[b] != s.segment[i] || s.segment[e] != s.segment[i]) continue;
      const Eigen::Vector2d u = p - s.segmented[b].p, v = s.segmented[e].p - p;
      f[i][k] = std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v));  // signed turning angle
    }
  }
  return f;
}

namespace {

// Sparse pairwise table of one edge: for each state j of the first node, the states k of the
// second node with a non-negligible distance-consistency term g(j, k) (CSR layout).
struct EdgeTable {
  int a = 0, b = 0;                 // node indices
  std::vector<int> row;             // size M + 1
  std::vector<int> col;
  std::vector<double> val;
};

}  // namespace

RegistrationResult crfMatch(const PointSet& reference, const PointSet& moving, const Pose2& guess,
                            const CrfOptions& options, CrfDiagnostics* diagnostics) {
  RegistrationResult result;
  result.transform = guess;
  CrfDiagnostics diag;
  const SubsamplingResult ref = subsample(reference, options.subsampling);
  const SubsamplingResult mov = subsample(moving, options.subsampling);
  const int M = static_cast<int>(ref.points.size());
  const int N = static_cast<int>(mov.points.size());
  diag.nodes = N;
  diag.states = M + 1;
  const int min_assoc = std::max(3, options.min_associations);
  if (M < min_assoc || N < min_assoc) {
    std::ostringstream os;
    os << "too few points after subsampling (reference " << M << ", moving " << N << "; need "
       << min_assoc << ")";
    result.failure_reason = os.str();
    if (diagnostics) *diagnostics = diag;
    return result;
  }
  const int S = M + 1;  // states: reference points + outlier
  const int OUT = M;

  // Local potentials.
  const auto fa_all = crfShapeFeatures(ref, options.feature_radii_m);
  const auto fb_all = crfShapeFeatures(mov, options.feature_radii_m);
  const size_t F = options.feature_radii_m.size();
  const double inv2s2 = 1.0 / (2.0 * options.feature_sigma_rad * options.feature_sigma_rad);
  std::vector<double> phi(static_cast<size_t>(N) * S);
  const Rigid2 G = Rigid2::fromPose(guess);
  for (int i = 0; i < N; ++i) {
    const auto& fb = fb_all[mov.selected[i]];
    for (int j = 0; j < M; ++j) {
      const auto& fa = fa_all[ref.selected[j]];
      double cost = 0;
      for (size_t k = 0; k < F; ++k) {
        const bool ha = std::isfinite(fa[k]), hb = std::isfinite(fb[k]);
        if (ha && hb) {
          const double d = common::wrapToPi(fa[k] - fb[k]);
          cost += d * d * inv2s2;
        } else if (ha != hb) {
          cost += options.missing_feature_cost;
        }
      }
      if (options.guess_sigma_m > 0)
        cost += (G * mov.points[i].p - ref.points[j].p).squaredNorm() /
                (2 * options.guess_sigma_m * options.guess_sigma_m);
      phi[static_cast<size_t>(i) * S + j] = std::exp(-cost);
    }
    phi[static_cast<size_t>(i) * S + OUT] = options.outlier_local;
  }

  // Reference distances, each row sorted, so that an edge's table is a range search per row.
  std::vector<std::vector<std::pair<double, int>>> sorted_d(M);
  for (int j = 0; j < M; ++j) {
    sorted_d[j].reserve(M - 1);
    for (int k = 0; k < M; ++k)
      if (k != j) sorted_d[j].emplace_back((ref.points[j].p - ref.points[k].p).norm(), k);
    std::sort(sorted_d[j].begin(), sorted_d[j].end());
  }
  const double ps = options.pair_sigma_m;
  const double cut = 3.0 * ps;
  std::vector<EdgeTable> edges;
  for (int s : options.edge_offsets) {
    if (s <= 0) continue;
    for (int i = 0; i + s < N; ++i) {
      EdgeTable e;
      e.a = i;
      e.b = i + s;
      const double d = (mov.points[i].p - mov.points[i + s].p).norm();
      e.row.assign(M + 1, 0);
      for (int j = 0; j < M; ++j) {
        e.row[j] = static_cast<int>(e.col.size());
        const auto& row = sorted_d[j];
        auto it = std::lower_bound(row.begin(), row.end(), std::make_pair(d - cut, -1));
        for (; it != row.end() && it->first <= d + cut; ++it) {
          const double x = (it->first - d) / ps;
          e.col.push_back(it->second);
          e.val.push_back(std::exp(-0.5 * x * x));
        }
      }
      e.row[M] = static_cast<int>(e.col.size());
      edges.push_back(std::move(e));
    }
  }
  diag.edges = static_cast<int>(edges.size());

  // Loopy belief propagation. msg[2e] : a -> b, msg[2e+1] : b -> a, each over S states.
  const size_t E = edges.size();
  std::vector<double> msg(2 * E * S, 1.0 / S);
  std::vector<std::vector<std::pair<int, int>>> incident(N);  // (edge, direction into node)
  for (size_t e = 0; e < E; ++e) {
    incident[edges[e].b].emplace_back(static_cast<int>(e), 0);  // msg 2e arrives at b
    incident[edges[e].a].emplace_back(static_cast<int>(e), 1);  // msg 2e+1 arrives at a
  }
  std::vector<double> belief(static_cast<size_t>(N) * S);
  auto computeBeliefs = [&]() {
    for (int i = 0; i < N; ++i) {
      double* bl = &belief[static_cast<size_t>(i) * S];
      const double* ph = &phi[static_cast<size_t>(i) * S];
      for (int j = 0; j < S; ++j) bl[j] = ph[j];
      for (const auto& [e, dir] : incident[i]) {
        const double* m = &msg[(2 * static_cast<size_t>(e) + dir) * S];
        double z = 0;
        for (int j = 0; j < S; ++j) z += (bl[j] *= m[j]);
        if (z > 0) for (int j = 0; j < S; ++j) bl[j] /= z;  // keep the products in range
      }
    }
  };
  std::vector<double> h(S), out(S);
  std::vector<double> next(msg.size());
  int iter = 0;
  for (iter = 1; iter <= options.bp_iterations; ++iter) {
    computeBeliefs();
    double change = 0;
    for (size_t e = 0; e < E; ++e) {
      const EdgeTable& t = edges[e];
      for (int dir = 0; dir < 2; ++dir) {
        // dir 0: from a to b (uses belief of a without the b -> a message); dir 1: b to a.
        const int from = dir == 0 ? t.a : t.b;
        const double* back = &msg[(2 * e + (dir == 0 ? 1 : 0)) * S];
        const double* bl = &belief[static_cast<size_t>(from) * S];
        double hs = 0;
        for (int j = 0; j < S; ++j) {
          h[j] = bl[j] / std::max(back[j], 1e-300);
          hs += h[j];
        }
        const double h_states = hs - h[OUT];
        // psi(j,k) = floor + g(j,k) for two reference points (g symmetric in j, k, so the same
        // table serves both directions), outlier_pair when either side is the outlier state.
        for (int k = 0; k < M; ++k) out[k] = options.pair_floor * h_states + options.outlier_pair * h[OUT];
        for (int j = 0; j < M; ++j) {
          if (h[j] == 0) continue;
          for (int q = t.row[j]; q < t.row[j + 1]; ++q) out[t.col[q]] += t.val[q] * h[j];
        }
        out[OUT] = options.outlier_pair * hs;
        double z = 0;
        for (int k = 0; k < S; ++k) z += out[k];
        double* dst = &next[(2 * e + dir) * S];
        const double* old = &msg[(2 * e + dir) * S];
        for (int k = 0; k < S; ++k) {
          const double v = (1.0 - options.bp_damping) * (out[k] / z) + options.bp_damping * old[k];
          change = std::max(change, std::abs(v - old[k]));
          dst[k] = v;
        }
      }
    }
    msg.swap(next);
    if (change < options.bp_tolerance) break;
  }
  diag.bp_iterations = std::min(iter, options.bp_iterations);
  computeBeliefs();

  // Most probable association of each moving point, weighted by its marginal.
  std::vector<Eigen::Vector2d> src, dst;
  std::vector<double> w;
  std::vector<int> mi, rj;
  for (int i = 0; i < N; ++i) {
    const double* bl = &belief[static_cast<size_t>(i) * S];
    int best = 0;
    for (int j = 1; j < S; ++j)
      if (bl[j] > bl[best]) best = j;
    if (best == OUT || bl[best] < options.min_marginal) continue;
    src.push_back(mov.points[i].p);
    dst.push_back(ref.points[best].p);
    w.push_back(bl[best]);
    mi.push_back(mov.source[mov.selected[i]]);
    rj.push_back(ref.source[ref.selected[best]]);
  }
  diag.associations = static_cast<int>(src.size());
  result.iterations = diag.bp_iterations;
  Pose2 T;
  if (static_cast<int>(src.size()) < min_assoc || !leastSquaresTransform(src, dst, w, &T)) {
    std::ostringstream os;
    os << "only " << src.size() << " confident associations (need " << min_assoc << ")";
    result.failure_reason = os.str();
    if (diagnostics) *diagnostics = diag;
    return result;
  }
  // Re-estimate on the inliers with a shrinking gate: a few confident but wrong associations
  // (repeated structure) must not pull the transform.
  std::vector<char> inlier(src.size(), 1);
  for (double gate : {4.0 * options.inlier_gate_m, 2.0 * options.inlier_gate_m, options.inlier_gate_m}) {
    const Rigid2 R = Rigid2::fromPose(T);
    std::vector<Eigen::Vector2d> s2, d2;
    std::vector<double> w2;
    for (size_t k = 0; k < src.size(); ++k) {
      inlier[k] = (R * src[k] - dst[k]).norm() < gate;
      if (!inlier[k]) continue;
      s2.push_back(src[k]);
      d2.push_back(dst[k]);
      w2.push_back(w[k]);
    }
    if (static_cast<int>(s2.size()) < min_assoc) break;
    Pose2 T2;
    if (leastSquaresTransform(s2, d2, w2, &T2)) T = T2;
  }
  const Rigid2 R = Rigid2::fromPose(T);
  double sse = 0;
  for (size_t k = 0; k < src.size(); ++k) {
    const double r = (R * src[k] - dst[k]).norm();
    if (r >= options.inlier_gate_m) continue;
    result.matches.push_back({mi[k], rj[k], w[k]});
    sse += r * r;
  }
  diag.inliers = static_cast<int>(result.matches.size());
  result.transform = T;
  result.rms_residual_m = result.matches.empty() ? 0 : std::sqrt(sse / result.matches.size());
  if (diag.inliers < min_assoc) {
    std::ostringstream os;
    os << "only " << diag.inliers << " of " << diag.associations
       << " associations agree on one transform (need " << min_assoc << ")";
    result.failure_reason = os.str();
  } else {
    result.converged = true;
  }
  if (diagnostics) *diagnostics = diag;
  return result;
}

}  // namespace urbanslam::alignment
