#pragma once
// Accuracy of a run against ground truth:
//  * the relation metric of Kümmerle et al. 2009 exactly as Cartographer computes it:
//    error = (p1⁻¹·p2)·expected⁻¹, absolute and squared translational [m, m²] and rotational
//    [deg, deg²] error, each mean ± std (n−1);
//  * ATE (RMSE of positions after the best rigid alignment) and RPE against a reference
//    trajectory;
//  * loop closures classified true/false against the reference (thesis §5.6).
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::evaluation {

struct Relation {
  double t1 = 0, t2 = 0;
  common::Pose2 expected;  // pose at t2 in the frame of the pose at t1
};

// Freiburg relation file: "t1 t2 x y z roll pitch yaw" per line. Throws common::InputError.
std::vector<Relation> readRelations(const std::string& path);

struct MeanStd {
  double mean = 0, std = 0;
};

struct RelationMetrics {
  size_t used = 0, skipped = 0;  // relations whose times fall outside the trajectory are skipped
  MeanStd abs_trans_m, sqr_trans_m2, abs_rot_deg, sqr_rot_deg2;
  double time_offset_s = 0;  // added to the trajectory's timestamps
};

// Pose of a time-sorted trajectory at time t by linear interpolation; false outside its span
// or across a gap longer than max_gap_s.
bool interpolatePose(const std::vector<io::StampedPose>& traj, double t, double max_gap_s, common::Pose2& out);

// A run's nodes (the scans it placed) at every time of `dense` (its trajectory at odometry times)
// inside the nodes' span, and at their own times. Between two nodes the pose follows dense's
// shape: dense's motion carried forward from the earlier node and backward from the later one,
// blended by time. So it equals each node at its time, and between nodes seconds apart it keeps
// the turn the odometry saw instead of cutting the chord (linear interpolation, what nodes
// without a dense companion get). Either input in any time order; times outside dense's span
// are interpolated linearly.
std::vector<io::StampedPose> bridgeNodes(const std::vector<io::StampedPose>& nodes, const std::vector<io::StampedPose>& dense);

RelationMetrics relationMetrics(const std::vector<io::StampedPose>& traj, const std::vector<Relation>& rel, double time_offset_s,
                                double max_gap_s = 1.0);

// Where the error comes from: each relation by where its two times fall among the scans the run
// placed by scan matching (`scan_times`, in the trajectory's time base, any order):
//  * at_scans: both ends within at_scan_s of a scan;
//  * one_interval: both ends strictly inside one interval between two consecutive scans (no
//    scan at or between them), where the run has nothing but the odometry;
//  * other: the rest (an end between scans and a scan in between, or outside the scans' span).
// A class's share is its error sum over all used relations: the three shares add up to the mean.
struct RelationClass {
  size_t n = 0;
  double abs_trans_mean_m = 0, share_m = 0;
};
struct RelationsByScans {
  RelationClass at_scans, one_interval, other;
};
RelationsByScans relationsByScans(const std::vector<io::StampedPose>& traj, const std::vector<Relation>& rel, double time_offset_s,
                                  const std::vector<double>& scan_times, double max_gap_s = 1.0, double at_scan_s = 0.002);

// The offset to add to the trajectory's timestamps so that it matches the relations' time base.
// Coarse, then refined to 0.5 ms: the one that minimises the relation error of `reference`
// (e.g. the corrected log's own poses). Exact: when relation times are sensor times of the log,
// the most frequent difference between a relation time and a timestamp of the log (`log_times`,
// e.g. its odometry times) within a second of the refined value — kept only if the reference
// fits the relations as well there (a re-stamped log shares no times with the relations).
// Returns 0 when the time bases already overlap.
double findRelationTimeOffset(const std::vector<io::StampedPose>& reference, const std::vector<Relation>& rel,
                              const std::vector<double>& log_times = {});

struct TrajectoryMetrics {
  size_t matched = 0;
  double ate_rmse_m = 0, ate_max_m = 0;
  double rpe_trans_rmse_m = 0, rpe_rot_rmse_deg = 0;  // between consecutive matched poses
  bool positions_only = false;                        // reference without headings (GPS)
  std::vector<double> times, errors_m;                // per matched pose, after alignment (for plots)
  std::vector<io::StampedPose> aligned;               // the estimate, rigidly aligned onto the reference
  common::Pose2 alignment;                            // the rigid transform from the estimate's frame to the reference's
};

// Matches every reference pose to the estimate at the same time (interpolated), aligns the
// estimate with the closed-form 2D rigid transform (Horn / Umeyama without scale), reports errors.
TrajectoryMetrics trajectoryMetrics(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& reference,
                                    bool positions_only, double max_gap_s = 1.0);

struct LoopRow {
  long from_keyframe = 0, to_keyframe = 0;
  double from_time = 0, to_time = 0;
  bool accepted = false;
  common::Pose2 measurement;
};
std::vector<LoopRow> readLoopClosuresCsv(const std::string& path);

// A false closure and how far its measurement is from the reference's relative pose, so a user
// can look at each one (they are listed, not only counted).
struct FalseClosure {
  long from_keyframe = 0, to_keyframe = 0;
  double from_time = 0, to_time = 0;
  double error_m = 0, error_deg = 0;  // for a positions-only reference: the distance disagreement
  common::Pose2 measurement;          // the run's relative pose (B in A's frame)
  common::Pose2 reference;            // the reference's (position-only references: heading 0)
};
struct LoopMetrics {
  size_t accepted = 0, true_positive = 0, false_positive = 0, unverifiable = 0;
  std::vector<FalseClosure> false_closures;
};
// An accepted closure is true when its measured relative pose agrees with the reference's
// relative pose of the two times within the tolerances (§5.6), false otherwise.
LoopMetrics classifyLoopClosures(const std::vector<LoopRow>& loops, const std::vector<io::StampedPose>& reference, bool positions_only,
                                 double tol_m = 0.5, double tol_deg = 5.0);

// Accepted closures checked against the relations, which are independent of any corrected log:
// a closure (times a, b) is checkable when a relation (t1, t2), in either direction, has
// |t1 - a| and |t2 - b| both within bridge_s; the relation is carried to the closure's times by
// the run's own nodes over those short legs, (node(a)^-1 node(t1)) relation (node(t2)^-1 node(b)),
// and the closure is contradicted when its measurement differs from that by more than the
// tolerances. The nearest relation (smallest |t1 - a| + |t2 - b|) decides.
struct RelationLoopCheck {
  size_t accepted = 0, checked = 0, contradicted = 0;
  std::vector<FalseClosure> contradictions;  // reference: the relation carried to the closure's times
};
RelationLoopCheck checkLoopsWithRelations(const std::vector<LoopRow>& loops, const std::vector<io::StampedPose>& nodes,
                                          const std::vector<Relation>& rel, double time_offset_s, double bridge_s = 3.0, double tol_m = 0.5,
                                          double tol_deg = 5.0);

}  // namespace urbanslam::evaluation
