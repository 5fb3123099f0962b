#include "urbanslam/esdf/PoseGraphBackend.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Recovery.h"

namespace urbanslam::esdf {
namespace {

// An incremental full recovery: Gauss-Newton steps from the current linearisation, each followed
// by relinearising the factors of the poses that moved (the next recovery, full or partial,
// then starts from the fresh linearisation without another factorisation here).
RecoveryStats incrementalRecovery(Esdf& filter, const PoseGraphBackendOptions& opt, int extra_steps = 0) {
  RecoveryStats st = filter.recover(std::max(0, opt.incremental_relinearise_passes - 1) + extra_steps);
  common::Stopwatch sw;
  const long long moved = filter.relinearise();
  st.factors_relinearised += moved;
  if (moved > 0) ++st.relinearise_passes;
  st.seconds += sw.seconds();
  return st;
}

// The backend; `current` follows the edge being added, for errors.
PoseGraphBackendResult runBackend(const PoseGraph& g, const PoseGraphBackendOptions& opt, const PoseGraphEdge** current) {
  PoseGraphBackendResult res;
  // Vertex ids: those declared plus those only named by edges (edges-only files).
  std::vector<long> ids;
  ids.reserve(g.vertices.size() + g.edges.size());
  for (const auto& v : g.vertices) ids.push_back(v.id);
  for (const auto& e : g.edges) {
    ids.push_back(e.from);
    ids.push_back(e.to);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  if (ids.empty()) throw common::InputError(g.name + ": pose graph has no vertices");
  std::unordered_map<long, int> index;
  index.reserve(ids.size());
  for (size_t k = 0; k < ids.size(); ++k) index.emplace(ids[k], static_cast<int>(k));
  const int n = static_cast<int>(ids.size());

  // Bucket edges by their later endpoint: they become usable when that pose is added.
  std::vector<int> bucket_start(static_cast<size_t>(n) + 1, 0);
  std::vector<int> order(g.edges.size());
  {
    std::vector<int> later(g.edges.size());
    for (size_t e = 0; e < g.edges.size(); ++e) {
      later[e] = std::max(index[g.edges[e].from], index[g.edges[e].to]);
      ++bucket_start[static_cast<size_t>(later[e]) + 1];
    }
    for (int k = 0; k < n; ++k) bucket_start[k + 1] += bucket_start[k];
    std::vector<int> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (size_t e = 0; e < g.edges.size(); ++e) order[static_cast<size_t>(fill[later[e]]++)] = static_cast<int>(e);
  }

  Vec3 first_pose = Vec3::Zero();
  for (const auto& v : g.vertices)
    if (v.id == ids[0]) first_pose = v.pose;

  common::Stopwatch total;
  Esdf filter(opt.filter);
  filter.reserve(n);
  const Vec3 anchor_var(opt.anchor_sigma_m * opt.anchor_sigma_m, opt.anchor_sigma_m * opt.anchor_sigma_m,
                        opt.anchor_sigma_rad * opt.anchor_sigma_rad);
  filter.initialise(first_pose, anchor_var.asDiagonal());
  res.step_ms.reserve(g.edges.size());

  int pending = 0;
  int last_full_size = 1;
  for (int k = 1; k < n; ++k) {
    const int b0 = bucket_start[k], b1 = bucket_start[k + 1];
    // The augmenting edge: to the previous pose when there is one, else the first edge.
    int aug = -1;
    for (int q = b0; q < b1; ++q) {
      const auto& e = g.edges[static_cast<size_t>(order[q])];
      const int other = index[e.from] == k ? index[e.to] : index[e.from];
      if (other == k - 1) {
        aug = q;
        break;
      }
      if (aug < 0) aug = q;
    }
    if (aug < 0)
      throw common::InputError(g.name + ": vertex " + std::to_string(ids[k]) + " has no edge to an earlier vertex (disconnected graph)");
    double max_chi2 = 0;
    int closures = 0;
    // The augmenting edge first (the new pose must exist before it is observed).
    std::swap(order[static_cast<size_t>(b0)], order[static_cast<size_t>(aug)]);
    aug = b0;
    for (int q = b0; q < b1; ++q) {
      common::Stopwatch sw;
      const auto& e = g.edges[static_cast<size_t>(order[q])];
      *current = &e;
      const int a = index[e.from], b = index[e.to];
      if (q == aug) {
        if (b == k)
          filter.augmentRelative(a, e.measurement, e.information);
        else  // an edge new -> earlier: kept as given so that its g2o error is what is minimised
          filter.augmentRelative(b, e.measurement, e.information, true);
        ++res.augment_edges;
      } else {
        if (opt.dead_reckoning_only) {
          res.step_ms.push_back(sw.milliseconds());
          continue;
        }
        bool accepted = true;
        if (opt.gate_loop_closures) {
          GateResult gr = filter.gateRelative(a, b, e.measurement, e.information);
          if (!gr.accepted && pending > 0) {
            // The mean may be stale (recoveries deferred): judge the closure on a fresh one.
            const RecoveryStats st = incrementalRecovery(filter, opt);
            res.recovery_s += st.seconds;
            res.factors_relinearised += st.factors_relinearised;
            ++res.full_recoveries;
            pending = 0;
            gr = filter.gateRelative(a, b, e.measurement, e.information);
          }
          accepted = gr.accepted;
        }
        ++res.observation_edges;
        if (accepted) {
          double dh = std::fabs(relativePoseError(filter.mean(a), filter.mean(b), e.measurement).z());
          if (dh > opt.full_recovery_heading_innovation_rad && pending > 0) {
            // The estimate is too stale to linearise this closure on the right branch: bring
            // it up to date first (whatever the spacing of full recoveries says).
            RecoveryStats st;
            common::Stopwatch sw_forced;
            if (opt.reinitialise_from_headings && opt.filter.relinearise) {
              st.factors_relinearised = filter.reinitialiseFromHeadings();
              if (opt.heading_recovery_steps > 0)
                st.factors_relinearised += incrementalRecovery(filter, opt, opt.heading_recovery_steps - 1).factors_relinearised;
            } else {
              st = incrementalRecovery(filter, opt, 1);  // a second step: the closure is linearised next
            }
            st.seconds = sw_forced.seconds();
            res.recovery_s += st.seconds;
            res.factors_relinearised += st.factors_relinearised;
            ++res.full_recoveries;
            ++res.heading_triggered_recoveries;
            pending = 0;
            dh = std::fabs(relativePoseError(filter.mean(a), filter.mean(b), e.measurement).z());
          }
          res.max_heading_innovation_rad = std::max(res.max_heading_innovation_rad, dh);
          const double diff = filter.mean(b).z() - filter.mean(a).z();
          res.closure_branches.push_back({order[q], diff - common::wrapToPi(diff - e.measurement.z())});
          if (dh > M_PI / 2) ++res.large_heading_innovations;
        }
        ObservationResult r;
        r.accepted = accepted;
        if (accepted) r = filter.observeRelative(a, b, e.measurement, e.information, false);
        if (!r.accepted) {
          ++res.rejected_edges;
        } else {
          ++closures;
          max_chi2 = std::max(max_chi2, r.chi2);
        }
      }
      if (q + 1 == b1 && closures > 0) {
        pending += closures;
        const bool wanted = pending >= opt.full_recovery_every_closures || max_chi2 > opt.full_recovery_innovation_chi2;
        const bool allowed = k + 1 - last_full_size >= opt.full_recovery_min_gap_fraction * last_full_size;
        if (wanted && allowed) {
          last_full_size = k + 1;
          const RecoveryStats st = incrementalRecovery(filter, opt);
          res.recovery_s += st.seconds;
          res.factors_relinearised += st.factors_relinearised;
          ++res.full_recoveries;
          pending = 0;
        } else {
          filter.recoverRecent(k - opt.recent_window_poses);
          ++res.partial_recoveries;
        }
      }
      res.step_ms.push_back(sw.milliseconds());
    }
  }
  {
    common::Stopwatch sw;
    const RecoveryStats st = filter.recover();
    res.recovery_s += st.seconds;
    res.factors_relinearised += st.factors_relinearised;
    res.final_relinearise_passes = st.relinearise_passes;
    res.converged = st.converged;
    ++res.full_recoveries;
    if (!res.step_ms.empty()) res.step_ms.back() += sw.milliseconds();
  }
  res.time_s = total.seconds();
  res.edges = static_cast<int>(g.edges.size());
  res.memory_bytes = filter.memoryBytes();
  res.vertex_ids = ids;
  res.poses.resize(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    res.poses[static_cast<size_t>(k)] = filter.mean(k);
    res.poses[static_cast<size_t>(k)].z() = common::wrapToPi(filter.mean(k).z());
  }
  res.chi2 = poseGraphChi2(g, res.poses, ids);
  return res;
}

}  // namespace

PoseGraphBackendResult runPoseGraphBackend(const PoseGraph& g, const PoseGraphBackendOptions& opt) {
  const PoseGraphEdge* current = nullptr;
  try {
    return runBackend(g, opt, &current);
  } catch (const NotPositiveDefinite& ex) {
    // Information matrices that are each positive definite can still sum to a Lambda that is not
    // numerically so (entries many orders of magnitude apart, measurements that contradict the
    // rest by far): name the edge after which the filter found it.
    std::string where = g.name;
    if (current) {
      if (current->line > 0) where += ":" + std::to_string(current->line);
      where += ": edge " + std::to_string(current->from) + " -> " + std::to_string(current->to);
    }
    throw common::InputError(where + ": the filter's " + ex.what() +
                             " after this edge (an extreme or inconsistent information matrix or measurement)");
  }
}

PoseGraph withPoses(const PoseGraph& graph, const PoseGraphBackendResult& r) {
  PoseGraph out;
  out.format = graph.format;
  out.edges = graph.edges;
  out.vertices.reserve(r.poses.size());
  for (size_t k = 0; k < r.poses.size(); ++k) out.vertices.push_back({r.vertex_ids[k], r.poses[k]});
  return out;
}

}  // namespace urbanslam::esdf
