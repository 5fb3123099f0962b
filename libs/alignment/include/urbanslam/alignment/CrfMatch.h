#pragma once
// CRF-match (thesis §3.3.2; Ramos, Fox & Durrant-Whyte, "CRF-Matching: Conditional Random
// Fields for Feature-Based Scan Matching", 2007).
//
// Both scans are subsampled (Subsampling.h). Each point i of the moving scan is a hidden
// variable x_i whose value is the reference point it corresponds to, or an outlier state (the
// point is not seen in the other scan). The conditional random field has
//  * local potentials phi_i(x_i) comparing shape features that a rigid transform does not
//    change: signed turning angles of the scan polyline at several radii around the point;
//  * pairwise potentials psi(x_i, x_k) between points i, k linked in the moving scan (sweep
//    neighbours plus longer links at several offsets): the distance |b_i - b_k| must reappear as
//    |a_{x_i} - a_{x_k}|, and the direction from each point to the other, measured from the
//    local sweep tangent, must reappear too (distances alone admit mirror images); a small
//    floor keeps every joint assignment possible.
// The graph has loops (the longer links), so marginals come from loopy belief propagation
// (sum-product, damped, flooding schedule). Where the scene repeats itself the marginals mix
// several hypotheses, so the few most probable associations of each point enter a consensus
// step (two-association hypotheses scored by the marginal mass they explain) that picks one
// association per point; these, weighted by their marginals, give the weighted least-squares
// transform.
//
// No initial guess is needed: the features and the distance consistency are invariant to the
// transform. The thesis uses CRF-match for the coarse alignment and ICP to refine (Aligner.h).
#include <vector>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/alignment/Registration.h"
#include "urbanslam/alignment/Subsampling.h"

namespace urbanslam::alignment {

struct CrfOptions {
  // CRF-match is quadratic in the points: fewer nodes than the thesis's 100 keep it near 10 ms
  // (bench: 90 nodes gained a few per cent of success for three times the time).
  SubsamplingOptions subsampling = [] {
    SubsamplingOptions o;
    o.target_points = 60;
    return o;
  }();
  std::vector<double> feature_radii_m = {0.3, 0.8, 2.0};  // turning-angle scales
  double feature_sigma_rad = 0.3;                         // width of the local potential per feature
  double missing_feature_cost = 1.0;                      // -log phi when a feature exists in one scan only
  double pair_sigma_m = 0.2;                              // width of the distance-consistency potential
  double pair_direction_sigma_rad = 0.35;                 // width of the relative-direction term (0 = off)
  double tangent_radius_m = 0.3;                          // the sweep tangent at a point spans this radius
  double pair_floor = 1e-3;                               // psi floor: no joint assignment is impossible
  double outlier_local = 0.05;                            // phi of the outlier state (a perfect feature match is 1)
  double outlier_pair = 0.05;                             // psi between the outlier state and anything
  std::vector<int> edge_offsets = {1, 4, 13};             // links i -- i+s among the subsampled points
  int bp_iterations = 15;
  double bp_damping = 0.5;         // new message = (1 - damping) * computed + damping * old
  double bp_tolerance = 1e-4;      // max change of any message to stop early
  double min_marginal = 0.05;      // associations less probable than this are not used
  int candidates_per_point = 3;    // most probable states of each point entering the consensus
  int consensus_hypotheses = 300;  // two-association transform hypotheses scored
  unsigned seed = 1;               // of the hypothesis draws (results are reproducible)
  int hypotheses_kept = 4;         // distinct best hypotheses reported for verification
  double guess_sigma_m = 0;        // > 0: weak prior on the associations from the guess
  double inlier_gate_m = 0.3;      // final weighted least squares uses pairs closer than this
  int min_associations = 6;
};

struct CrfDiagnostics {
  int nodes = 0, states = 0, edges = 0, bp_iterations = 0, associations = 0, inliers = 0;
  std::vector<common::Pose2> hypotheses;  // distinct consensus hypotheses, best first (before WLS)
  double time_potentials_ms = 0, time_bp_ms = 0, time_transform_ms = 0;
  long table_entries = 0;  // non-negligible pairwise entries over all edges
};

// CRF-match of `moving` onto `reference`. `guess` only matters when guess_sigma_m > 0.
// Matches refer to indices of the input sets.
RegistrationResult crfMatch(const PointSet& reference, const PointSet& moving, const common::Pose2& guess, const CrfOptions& options,
                            CrfDiagnostics* diagnostics = nullptr);

// The transform-invariant shape features of the points of `subsampled.segmented` (one vector
// per point, NaN = undefined because the segment ends within the radius). Exposed for tests.
std::vector<std::vector<double>> crfShapeFeatures(const SubsamplingResult& subsampled, const std::vector<double>& radii_m);

}  // namespace urbanslam::alignment
