#include "urbanslam/alignment/CrfMatch.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "urbanslam/alignment/Icp.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/common/RigidFit.h"

namespace urbanslam::alignment {

using common::Pose2;

std::vector<std::vector<double>> crfShapeFeatures(const SubsamplingResult& s, const std::vector<double>& radii_m) {
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

// Wraps the difference of two angles in (-pi, pi] (so within (-2pi, 2pi)) without fmod.
inline double wrapDiff(double a) {
  if (a > M_PI) return a - 2 * M_PI;
  if (a <= -M_PI) return a + 2 * M_PI;
  return a;
}

// Direction of the scan polyline at each point of `segmented`, oriented along the sweep: from
// the first point at least `radius` behind to the first at least `radius` ahead (within the
// segment; the segment's ends fall back to the nearest available neighbour).
std::vector<double> sweepTangents(const SubsamplingResult& s, double radius) {
  const int n = static_cast<int>(s.segmented.size());
  std::vector<double> t(n, 0.0);
  const double r2 = radius * radius;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = s.segmented[i].p;
    int b = i, e = i;
    while (b - 1 >= 0 && s.segment[b - 1] == s.segment[i] && (s.segmented[b].p - p).squaredNorm() < r2) --b;
    while (e + 1 < n && s.segment[e + 1] == s.segment[i] && (s.segmented[e].p - p).squaredNorm() < r2) ++e;
    const Eigen::Vector2d d = s.segmented[e].p - s.segmented[b].p;
    t[i] = std::atan2(d.y(), d.x());
  }
  return t;
}

// Sparse pairwise table of one edge: for each state j of the first node, the states k of the
// second node with a non-negligible distance-consistency term g(j, k) (CSR layout).
struct EdgeTable {
  int a = 0, b = 0;      // node indices
  std::vector<int> row;  // size M + 1
  std::vector<int> col;
  std::vector<double> val;
};

}  // namespace

RegistrationResult crfMatch(const PointSet& reference, const PointSet& moving, const Pose2& guess, const CrfOptions& options,
                            CrfDiagnostics* diagnostics) {
  RegistrationResult result;
  result.transform = guess;
  CrfDiagnostics diag;
  common::Stopwatch sw;
  const SubsamplingResult ref = subsample(reference, options.subsampling);
  const SubsamplingResult mov = subsample(moving, options.subsampling);
  const int M = static_cast<int>(ref.points.size());
  const int N = static_cast<int>(mov.points.size());
  diag.nodes = N;
  diag.states = M + 1;
  const int min_assoc = std::max(3, options.min_associations);
  if (M < min_assoc || N < min_assoc) {
    std::ostringstream os;
    os << "too few points after subsampling (reference " << M << ", moving " << N << "; need " << min_assoc << ")";
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
          const double d = wrapDiff(fa[k] - fb[k]);
          cost += d * d * inv2s2;
        } else if (ha != hb) {
          cost += options.missing_feature_cost;
        }
      }
      if (options.guess_sigma_m > 0)
        cost += (G * mov.points[i].p - ref.points[j].p).squaredNorm() / (2 * options.guess_sigma_m * options.guess_sigma_m);
      phi[static_cast<size_t>(i) * S + j] = std::exp(-cost);
    }
    phi[static_cast<size_t>(i) * S + OUT] = options.outlier_local;
  }

  // Pairwise geometry of the reference: distances (each row sorted, so that an edge's table is
  // a range search per row) and the direction to every other point relative to the local sweep
  // tangent. Distances alone are also preserved by a mirror image; the relative directions are
  // preserved by rotations only.
  const std::vector<double> tan_a_all = sweepTangents(ref, options.tangent_radius_m);
  const std::vector<double> tan_b_all = sweepTangents(mov, options.tangent_radius_m);
  std::vector<std::vector<std::pair<double, int>>> sorted_d(M);
  std::vector<double> rel_dir_a(static_cast<size_t>(M) * M, 0.0);
  for (int j = 0; j < M; ++j) {
    sorted_d[j].reserve(M - 1);
    const double tj = tan_a_all[ref.selected[j]];
    for (int k = 0; k < M; ++k) {
      if (k == j) continue;
      const Eigen::Vector2d d = ref.points[k].p - ref.points[j].p;
      sorted_d[j].emplace_back(d.norm(), k);
      rel_dir_a[static_cast<size_t>(j) * M + k] = common::wrapToPi(std::atan2(d.y(), d.x()) - tj);
    }
    std::sort(sorted_d[j].begin(), sorted_d[j].end());
  }
  const double ps = options.pair_sigma_m;
  const double cut = 3.0 * ps;
  const double inv_s2_dir =
      options.pair_direction_sigma_rad > 0 ? 1.0 / (options.pair_direction_sigma_rad * options.pair_direction_sigma_rad) : 0.0;
  const double keep = 1e-3;  // table entries below this (times the peak) fall to the floor
  const double max_q = -std::log(keep);
  std::vector<EdgeTable> edges;
  for (int s : options.edge_offsets) {
    if (s <= 0) continue;
    for (int i = 0; i + s < N; ++i) {
      EdgeTable e;
      e.a = i;
      e.b = i + s;
      const Eigen::Vector2d db = mov.points[i + s].p - mov.points[i].p;
      const double d = db.norm();
      const double dir_ab = common::wrapToPi(std::atan2(db.y(), db.x()) - tan_b_all[mov.selected[i]]);
      const double dir_ba = common::wrapToPi(std::atan2(-db.y(), -db.x()) - tan_b_all[mov.selected[i + s]]);
      e.row.assign(M + 1, 0);
      for (int j = 0; j < M; ++j) {
        e.row[j] = static_cast<int>(e.col.size());
        const auto& row = sorted_d[j];
        auto it = std::lower_bound(row.begin(), row.end(), std::make_pair(d - cut, -1));
        for (; it != row.end() && it->first <= d + cut; ++it) {
          const int k = it->second;
          const double x = (it->first - d) / ps;
          double q = 0.5 * x * x;
          if (inv_s2_dir > 0) {
            const double u = wrapDiff(rel_dir_a[static_cast<size_t>(j) * M + k] - dir_ab);
            const double v = wrapDiff(rel_dir_a[static_cast<size_t>(k) * M + j] - dir_ba);
            q += 0.5 * (u * u + v * v) * inv_s2_dir;
          }
          if (q > max_q) continue;  // cheaper than the exp below for the many rejected pairs
          const double g = std::exp(-q);
          if (g < keep) continue;
          e.col.push_back(k);
          e.val.push_back(g);
        }
      }
      e.row[M] = static_cast<int>(e.col.size());
      edges.push_back(std::move(e));
    }
  }
  diag.edges = static_cast<int>(edges.size());
  for (const auto& e : edges) diag.table_entries += static_cast<long>(e.col.size());

  diag.time_potentials_ms = sw.milliseconds();
  sw.restart();
  // Loopy belief propagation. msg[2e] : a -> b, msg[2e+1] : b -> a, each over S states.
  const size_t E = edges.size();
  std::vector<double> msg(2 * E * S, 1.0 / S);
  std::vector<std::vector<std::pair<int, int>>> incident(N);  // (edge, direction into node)
  for (size_t e = 0; e < E; ++e) {
    incident[edges[e].b].emplace_back(static_cast<int>(e), 0);  // msg 2e arrives at b
    incident[edges[e].a].emplace_back(static_cast<int>(e), 1);  // msg 2e+1 arrives at a
  }
  // The dense per-state loops below are written on Eigen arrays, which vectorise them (sums and
  // divisions included): belief propagation is most of CRF-match's time, and CRF-match most of
  // a loop closure's.
  using Arr = Eigen::Map<Eigen::ArrayXd>;
  using ConstArr = Eigen::Map<const Eigen::ArrayXd>;
  std::vector<double> belief(static_cast<size_t>(N) * S);
  auto computeBeliefs = [&]() {
    for (int i = 0; i < N; ++i) {
      Arr bl(&belief[static_cast<size_t>(i) * S], S);
      bl = ConstArr(&phi[static_cast<size_t>(i) * S], S);
      for (const auto& [e, dir] : incident[i]) {
        bl *= ConstArr(&msg[(2 * static_cast<size_t>(e) + dir) * S], S);
        const double z = bl.sum();
        if (z > 0) bl *= 1.0 / z;  // keep the products in range
      }
    }
  };
  std::vector<double> h(S), out(S);
  std::vector<double> next(msg.size());
  Arr hv(h.data(), S), outv(out.data(), S);
  int iter = 0;
  for (iter = 1; iter <= options.bp_iterations; ++iter) {
    computeBeliefs();
    double change = 0;
    for (size_t e = 0; e < E; ++e) {
      const EdgeTable& t = edges[e];
      for (int dir = 0; dir < 2; ++dir) {
        // dir 0: from a to b (uses belief of a without the b -> a message); dir 1: b to a.
        const int from = dir == 0 ? t.a : t.b;
        const ConstArr back(&msg[(2 * e + (dir == 0 ? 1 : 0)) * S], S);
        hv = ConstArr(&belief[static_cast<size_t>(from) * S], S) / back.max(1e-300);
        const double hs = hv.sum();
        const double h_states = hs - h[OUT];
        // psi(j,k) = floor + g(j,k) for two reference points (rows j: state of node a,
        // columns k: state of node b), outlier_pair when either side is the outlier state.
        outv.head(M).setConstant(options.pair_floor * h_states + options.outlier_pair * h[OUT]);
        if (dir == 0) {
          for (int j = 0; j < M; ++j) {
            if (h[j] == 0) continue;
            for (int q = t.row[j]; q < t.row[j + 1]; ++q) out[t.col[q]] += t.val[q] * h[j];
          }
        } else {
          for (int j = 0; j < M; ++j) {
            double acc = 0;
            for (int q = t.row[j]; q < t.row[j + 1]; ++q) acc += t.val[q] * h[t.col[q]];
            out[j] += acc;
          }
        }
        out[OUT] = options.outlier_pair * hs;
        const double z = outv.sum();
        Arr dst(&next[(2 * e + dir) * S], S);
        const ConstArr old(&msg[(2 * e + dir) * S], S);
        dst = ((1.0 - options.bp_damping) / z) * outv + options.bp_damping * old;
        change = std::max(change, (dst - old).abs().maxCoeff());
      }
    }
    msg.swap(next);
    if (change < options.bp_tolerance) break;
  }
  diag.bp_iterations = std::min(iter, options.bp_iterations);
  computeBeliefs();
  diag.time_bp_ms = sw.milliseconds();
  sw.restart();

  // Candidate associations: the few most probable states of each moving point. Where the
  // scene repeats itself (walls, corridors) the marginals are mixtures of several consistent
  // hypotheses, and the per-point maxima need not belong to the same one.
  struct Candidate {
    int node, state;
    double w;
  };
  std::vector<Candidate> cand;
  std::vector<int> order(M);
  for (int i = 0; i < N; ++i) {
    const double* bl = &belief[static_cast<size_t>(i) * S];
    for (int j = 0; j < M; ++j) order[j] = j;
    const int K = std::min(M, std::max(1, options.candidates_per_point));
    std::partial_sort(order.begin(), order.begin() + K, order.end(), [&](int x, int y) { return bl[x] > bl[y]; });
    for (int k = 0; k < K; ++k)
      if (bl[order[k]] >= options.min_marginal && bl[order[k]] > bl[OUT]) cand.push_back({i, order[k], bl[order[k]]});
  }
  diag.associations = static_cast<int>(cand.size());
  result.iterations = diag.bp_iterations;
  if (static_cast<int>(cand.size()) < min_assoc) {
    std::ostringstream os;
    os << "only " << cand.size() << " confident associations (need " << min_assoc << ")";
    result.failure_reason = os.str();
    if (diagnostics) *diagnostics = diag;
    return result;
  }
  // Consensus among the candidates: transforms from two associations (drawn in proportion to
  // their marginals), scored by the marginal mass of the points that one of their candidates
  // puts within the inlier gate. The best hypothesis selects one association per point.
  const double gate = options.inlier_gate_m;
  auto bestPerNode = [&](const Pose2& hyp, std::vector<int>* pick, double* score) {
    const Rigid2 R = Rigid2::fromPose(hyp);
    pick->assign(N, -1);
    std::vector<double> best_r(N, gate);
    for (size_t c = 0; c < cand.size(); ++c) {
      const double r = (R * mov.points[cand[c].node].p - ref.points[cand[c].state].p).norm();
      if (r < best_r[cand[c].node]) {
        best_r[cand[c].node] = r;
        (*pick)[cand[c].node] = static_cast<int>(c);
      }
    }
    *score = 0;
    for (int i = 0; i < N; ++i)
      if ((*pick)[i] >= 0) *score += cand[(*pick)[i]].w * (1.0 - best_r[i] / gate);
  };
  std::mt19937 rng(options.seed);
  std::vector<double> cw;
  for (const auto& c : cand) cw.push_back(c.w);
  std::discrete_distribution<size_t> draw(cw.begin(), cw.end());
  Pose2 T;
  double best_score = -1;
  std::vector<int> pick;
  std::vector<std::pair<double, Pose2>> ranked;
  for (int h = 0; h < options.consensus_hypotheses; ++h) {
    const Candidate& c1 = cand[draw(rng)];
    const Candidate& c2 = cand[draw(rng)];
    if (c1.node == c2.node || c1.state == c2.state) continue;
    const Eigen::Vector2d db = mov.points[c2.node].p - mov.points[c1.node].p;
    const Eigen::Vector2d da = ref.points[c2.state].p - ref.points[c1.state].p;
    if (db.norm() < 4 * gate || std::abs(db.norm() - da.norm()) > gate) continue;
    const double phi = common::wrapToPi(std::atan2(da.y(), da.x()) - std::atan2(db.y(), db.x()));
    const Eigen::Vector2d mb = 0.5 * (mov.points[c1.node].p + mov.points[c2.node].p);
    const Eigen::Vector2d ma = 0.5 * (ref.points[c1.state].p + ref.points[c2.state].p);
    const double c = std::cos(phi), s = std::sin(phi);
    const Pose2 hyp{ma.x() - (c * mb.x() - s * mb.y()), ma.y() - (s * mb.x() + c * mb.y()), phi};
    double score = 0;
    std::vector<int> p;
    bestPerNode(hyp, &p, &score);
    if (score > best_score) {
      best_score = score;
      T = hyp;
      pick = p;
    }
    // Keep the best few distinct hypotheses for a verifier (CRF+ICP) to choose from.
    bool merged = false;
    for (auto& [sc, ph] : ranked) {
      if (std::hypot(ph.x - hyp.x, ph.y - hyp.y) < 0.5 && std::abs(common::wrapToPi(ph.phi - hyp.phi)) < 0.1) {
        if (score > sc) {
          sc = score;
          ph = hyp;
        }
        merged = true;
        break;
      }
    }
    if (!merged) ranked.emplace_back(score, hyp);
    std::sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    if (static_cast<int>(ranked.size()) > std::max(1, options.hypotheses_kept)) ranked.resize(std::max(1, options.hypotheses_kept));
  }
  for (const auto& r : ranked) diag.hypotheses.push_back(r.second);
  if (best_score < 0) {
    result.failure_reason = "no two associations agree on a transform";
    if (diagnostics) *diagnostics = diag;
    return result;
  }
  // Weighted least squares on the chosen associations, re-selected once at the new transform.
  std::vector<Eigen::Vector2d> src, dst;
  std::vector<double> w;
  std::vector<int> mi, rj;
  for (int round = 0; round < 3; ++round) {
    src.clear();
    dst.clear();
    w.clear();
    mi.clear();
    rj.clear();
    for (int i = 0; i < N; ++i) {
      if (pick[i] < 0) continue;
      const Candidate& c = cand[pick[i]];
      src.push_back(mov.points[c.node].p);
      dst.push_back(ref.points[c.state].p);
      w.push_back(c.w);
      mi.push_back(mov.source[mov.selected[c.node]]);
      rj.push_back(ref.source[ref.selected[c.state]]);
    }
    Pose2 T2;
    if (static_cast<int>(src.size()) < min_assoc || !common::fitRigid2D(src, dst, w, &T2)) break;
    T = T2;
    double unused = 0;
    bestPerNode(T, &pick, &unused);
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
  diag.time_transform_ms = sw.milliseconds();
  result.transform = T;
  result.rms_residual_m = result.matches.empty() ? 0 : std::sqrt(sse / result.matches.size());
  if (diag.inliers < min_assoc) {
    std::ostringstream os;
    os << "only " << diag.inliers << " of " << diag.associations << " associations agree on one transform (need " << min_assoc << ")";
    result.failure_reason = os.str();
  } else {
    result.converged = true;
  }
  if (diagnostics) *diagnostics = diag;
  return result;
}

}  // namespace urbanslam::alignment
