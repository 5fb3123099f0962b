#pragma once
// Local scan matching with the motion prior and the scan evidence weighed by their
// uncertainties, in one formulation (Cartographer's real-time correlative matcher followed by
// its least-squares matcher):
//  1. correlative search (CorrelativeSearch.h): the pose maximising the scan's log-likelihood in
//     the reference's likelihood grid plus the log-density of the odometry prior (MotionPrior.h),
//     over a window that covers the prior's 3σ and at least the configured reach;
//  2. refinement by Gauss-Newton from that pose: point-to-line residuals against the reference
//     (point-to-point where a point has no line) under a Cauchy kernel, plus the prior's
//     residual weighted by its information and by the prior's Gaussian share at the estimate;
//  2'. when the best pose lies outside the odometry's Gaussian (the scan outvotes the odometry),
//     the best pose under its Gaussian alone is searched too, and the two are weighed again with the
//     free-space evidence of both sides: scan points where the reference's beams passed through,
//     reference points where the scan's did (BeamFreeSpace.h). A slide along a corridor or a turn
//     onto a look-alike wall puts walls where one of the two saw empty space; a reversing
//     odometry corrected by the scan does not. Each point in view weighs by the likelihood ratio
//     of what it shows (seen through or not) at a right pose against a wrong one: how often
//     points are seen through at right poses (moving people, glass; outdoors the ground on slopes
//     and vegetation) and at poses a little off, rates the caller learns from the matches
//     (SeenThroughRate.h) and gives here;
//  3. the covariance: the inverse of that Hessian, i.e. the posterior of the relative pose given
//     the odometry and the scan. Where the scan leaves a direction free (a corridor) the prior
//     holds it; a clear match far from a wrong odometry pays only the prior's bounded outlier
//     cost;
//  4. the spread the Hessian does not see: the search and the refinement estimate the same pose
//     from two models of the evidence (the likelihood grid of the thinned scan, the point-to-line
//     residuals of every point with their nearest-neighbour associations). Where they part (the
//     refinement's associations pulling it along a wall or round a turn the search had placed
//     right, mostly with sparse scans after a large turn) one of them is wrong by that much and
//     nothing in the match says which: the caller adds the second moment of the search's pose
//     about the estimate to the covariance, so that the filter's innovation gate admits the
//     loop closures that correct it and the correction goes where the doubt is.
// The search scores the scan's points thinned to one per voxel (a cheaper search whose
// evidence is not dominated by the many beams on the nearest wall); the refinement uses every
// point.
#include <string>

#include <Eigen/Core>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/LikelihoodGrid.h"
#include "urbanslam/alignment/LineNormals.h"
#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

struct PriorMatcherOptions {
  LikelihoodGridOptions grid;
  double voxel_m = 0.2;              // the search scores one point per voxel
  double search_window_m = 1.0;      // translation reach of the search (+-, each axis) at least
  double search_window_deg = 30.0;   // heading reach at least
  double max_search_window_m = 3.0;  // the prior's 3σ widens the window up to this
  double max_search_window_deg = 90.0;
  // The prior's 3σ of heading widens the heading window by this factor only (≤ 1: the heading
  // corrections seen so far are smaller than the prior says, HeadingCorrections.h); the prior's
  // weight, and the uniform share's density over the unscaled window, stay as they are.
  double heading_window_scale = 1.0;
  double odometry_outlier_probability = 1e-4;  // the prior's uniform share (MotionPrior.h)
  // How far from the prior's mean odometry that is wrong in direction (reversing reported as
  // driving forwards) can have put the vehicle: the window reaches at least this far. < 0: twice
  // the prior mean's distance from the reference's origin (the motion started there).
  double direction_reach_m = -1;
  // false: the search leaves that reach out and covers search_window_m and the prior's 3σ only
  // (a caller that searches again with it when the match is in doubt: odometry wrong in direction
  // explains the scan poorly there, or puts the best pose at the window's edge). The uniform
  // share's density stays that of the full window, so the prior, and a match inside the narrower
  // window, are the same.
  bool search_direction_reach = true;
  // The share of points in view that the other side saw through at the true pose, and at poses
  // displaced from it by displacement_m and displacement_deg (step 2'); 0: step 2' off.
  double seen_through_rate = 0.05;
  double seen_through_rate_displaced = 0.3;
  double displacement_m = 0.5;
  double displacement_deg = 10;
  // The result's free-space counts (in_view, seen_through and their displaced sums) are taken;
  // false leaves them 0 (a caller that needs them from only some matches saves their cost).
  bool count_free_space = true;
  double free_margin_m = 0.3;  // seen empty up to this + free_margin_fraction * range before a return
  double free_margin_fraction = 0.05;
  double point_sigma_m = 0.05;   // a return's distance to the reference surface (refinement)
  double kernel_scale_m = 0.05;  // Cauchy kernel scale
  double gate_m = 0.3;           // refinement associations farther than this are ignored
  int max_iterations = 30;
  int min_points = 10;  // fewer voxels: no match, the prior alone
  LineNormalOptions normals;
};

struct PriorMatchResult {
  bool valid = false;  // false: too few points, the prior is the answer
  std::string failure_reason;
  common::Pose2 pose;                                     // posterior mode: the scan's pose in the reference's frame
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();      // posterior covariance (x, y, phi) about pose, given its associations
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();       // what cov leaves out (step 4): (search_pose - pose)(search_pose - pose)'
  common::Pose2 search_pose;                              // the correlative search's pose
  double scan_log_likelihood = 0;                         // at search_pose
  double prior_weight = 1;                                // the prior's Gaussian share at the result (0: odometry outvoted)
  int voxels = 0, points = 0, matched = 0;                // thinned points, refinement points, associated at the end
  double rms_residual_m = 0;                              // distance of the associated points to their neighbours
  int in_view = 0, seen_through = 0;                      // at the result: thinned points of both sides the other side's beams reach, pass
  int displaced_in_view = 0, displaced_seen_through = 0;  // the same summed over four poses displaced from the result
  bool odometry_outvoted = false;                         // the result lies outside the odometry's Gaussian (after step 2')
  int iterations = 0, search_nodes = 0;
  double search_half_angle_rad = 0;  // the heading window searched (each side of the prior's mean)
  double search_half_width_m = 0;    // ... and the translation window (each side, along x and y)
  bool window_narrowed = false;      // the window searched is narrower than the prior's full one
  double time_ms = 0;
  double matchedFraction() const { return points > 0 ? static_cast<double>(matched) / points : 0.0; }
};

// One scan of the reference with the space its beams passed through, placed in the reference's
// frame.
struct ReferenceView {
  BeamFreeSpace beams;
  common::Pose2 pose;
};

// The reference prepared once for many matches (all the scans against one submap). views: the
// reference's scans with their free space (none: step 2' sees only the scan's side).
class MatchReference {
 public:
  MatchReference(PointSet points, const Eigen::Vector2d& centre, const PriorMatcherOptions& options, std::vector<ReferenceView> views = {});
  const IndexedReference& indexed() const { return indexed_; }
  const LikelihoodGrid& grid() const { return grid_; }
  const std::vector<ReferenceView>& views() const { return views_; }
  // The points thinned to one per voxel of the search (step 2' counts these).
  const std::vector<Eigen::Vector2d>& thinned() const { return thinned_; }

 private:
  IndexedReference indexed_;
  LikelihoodGrid grid_;
  std::vector<ReferenceView> views_;
  std::vector<Eigen::Vector2d> thinned_;
};

// `scan` (points in its own frame) matched onto `reference`, the odometry saying prior_mean with
// prior_cov.
PriorMatchResult matchWithPrior(const MatchReference& reference, const PointSet& scan, const common::Pose2& prior_mean,
                                const Eigen::Matrix3d& prior_cov, const PriorMatcherOptions& options);

}  // namespace urbanslam::alignment
