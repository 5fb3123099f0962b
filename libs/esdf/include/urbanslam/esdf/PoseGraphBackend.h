#pragma once
// Feeds a 2D pose graph to the ESDF incrementally, in vertex-id order, as a SLAM front end
// would: for each new pose, one edge to an earlier pose (the odometry edge id-1 -> id when
// present) is a prediction with augmentation, every other edge to earlier poses is a
// relative-pose observation. Between full recoveries, the recent poses are recovered
// partially; a full recovery (with relinearisation) follows every few loop closures or at once
// after a closure that disagrees strongly with the current estimate.
#include <string>
#include <vector>

#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseGraphIO.h"

namespace urbanslam::esdf {

struct PoseGraphBackendOptions {
  // The final recovery stops, as a batch solver does, once a Gauss-Newton step gains less than
  // 1e-6 of the cost (Ceres's function tolerance, which the benchmark's batch peer uses too).
  EsdfOptions filter = [] {
    EsdfOptions o;
    o.relinearise_cost_tolerance = 1e-6;
    o.commit_heading_branch = true;
    return o;
  }();
  // Gate loop closures with the chi2 test (filter.chi2_gate_probability). Off by default: the
  // benchmark graphs have no outliers and the batch reference uses every edge.
  bool gate_loop_closures = false;
  // Full recovery after this many loop closures since the last one...
  int full_recovery_every_closures = 20;
  // ...or at once when a closure's innovation chi2 e' Omega e exceeds this (the estimate is far
  // from what the closure says, so deferring would linearise later closures badly).
  double full_recovery_innovation_chi2 = 50.0;
  // A closure whose heading innovation exceeds this (rad) is preceded by a full recovery,
  // whatever the spacing below says, when closures were added since the last one: linearised
  // on an estimate that stale, its wrapped heading error may pick the wrong branch (a 2*pi
  // twist no later Gauss-Newton step undoes).
  double full_recovery_heading_innovation_rad = 1.0;
  // That recovery starts from the headings-first solution (Esdf::reinitialiseFromHeadings, with
  // every factor on the heading branch it was added on: filter.commit_heading_branch), then
  // takes this many Gauss-Newton steps, so the closure's branch is read off an estimate that
  // both the headings and the translations agree on. Without reinitialise_from_headings (or
  // without relinearisation), two Gauss-Newton steps from the stale estimate. On the
  // benchmark's 10^6-pose drive, Gauss-Newton steps alone end in a wrong-branch local minimum.
  bool reinitialise_from_headings = true;
  int heading_recovery_steps = 2;
  // ...but never sooner than this fraction of the trajectory after the previous one: full
  // recoveries then come at geometrically spaced sizes, so their total cost stays a small
  // multiple of one recovery of the final graph however many loop closures there are.
  double full_recovery_min_gap_fraction = 0.25;
  // Gauss-Newton steps in each incremental full recovery, each followed by relinearising the
  // moved factors (the final recovery iterates to convergence): one step per recovery keeps the
  // step cost at one factorisation while the linearisation error is still worked off over the
  // following recoveries.
  int incremental_relinearise_passes = 1;
  // Poses re-solved by the partial recovery after a loop closure that did not trigger a full one.
  int recent_window_poses = 50;
  // Only the augmenting edges (dead reckoning through the spanning edges; for initial guesses).
  bool dead_reckoning_only = false;
  // Pose 0's prior (anchors the gauge freedom, as fixing the first vertex does in g2o).
  double anchor_sigma_m = 1e-4;
  double anchor_sigma_rad = 1e-5;
};

struct PoseGraphBackendResult {
  std::vector<long> vertex_ids;  // sorted ids; poses[k] belongs to vertex_ids[k]
  std::vector<Vec3> poses;       // headings wrapped to (-pi, pi]
  double chi2 = 0;               // g2o/MRPT convention, sum e' Omega e over all edges
  int edges = 0, augment_edges = 0, observation_edges = 0, rejected_edges = 0;
  int full_recoveries = 0, partial_recoveries = 0;
  long long factors_relinearised = 0;
  int final_relinearise_passes = 0;
  bool converged = false;  // the final relinearisation ended with nothing left to relinearise
  // Loop closures whose heading innovation (at the estimate when they were added) exceeded
  // pi/2, and the largest one: a closure linearised that far off may land on the wrong branch.
  int large_heading_innovations = 0;
  int heading_triggered_recoveries = 0;  // full recoveries forced by full_recovery_heading_innovation_rad
  double max_heading_innovation_rad = 0;
  // Per loop closure as it was linearised: its edge index and the unwrapped heading difference
  // (heading of `to` minus heading of `from`) its heading error put it on. Against the true
  // headings this tells a closure added on the wrong branch (esdf_bench does so).
  struct ClosureBranch {
    int edge;
    double heading_diff_rad;
  };
  std::vector<ClosureBranch> closure_branches;
  std::vector<double> step_ms;  // processing time of each edge (recovery charged to the last edge of a step)
  double time_s = 0;            // filter time (excludes reading the file)
  double recovery_s = 0;        // of which full recoveries
  size_t memory_bytes = 0;      // filter storage at the end
};

PoseGraphBackendResult runPoseGraphBackend(const PoseGraph& graph, const PoseGraphBackendOptions& options = {});

// The graph with its vertices replaced by the given poses (for --out).
PoseGraph withPoses(const PoseGraph& graph, const PoseGraphBackendResult& result);

}  // namespace urbanslam::esdf
