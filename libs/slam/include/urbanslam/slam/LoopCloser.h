#pragma once
// Global SLAM (thesis ch. 5): for a new keyframe, the loop-closure candidates — an initial set of
// earlier keyframes near the current estimate, a final set by Mahalanobis distance with the
// recovered covariances (§5.2), picked by appearance (the laser classifier, §3.2) when the
// estimate is too uncertain to pick them — then alignment for the relative pose and its
// covariance (§5.3) and the innovation gate (§5.4) before the ESDF update.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/ViewOverlap.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/io/SpillLog.h"
#include "urbanslam/slam/CameraClosure.h"
#include "urbanslam/slam/KeyframeGrid.h"
#include "urbanslam/slam/KeyframeNodes.h"
#include "urbanslam/slam/MovingReturns.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/Proposer.h"

namespace urbanslam::alignment {
class IndexedReference;
}  // namespace urbanslam::alignment

namespace urbanslam::slam {

class Map;

// Why a loop-closure hypothesis did not become a constraint.
enum class ClosureReason {
  None,                 // accepted (or not decided yet)
  Alignment,            // the scans could not be aligned well enough
  Ambiguous,            // another alignment explains the scans about as well
  FreeSpace,            // one scan's points lie where the other scan's beams passed through
  Gating,               // the innovation gate refused it
  Unconfirmed,          // no second closure agreed with it in time
  NoScans,              // an image proposal between keyframes without laser scans (nor a calibrated camera)
  CameraGeometry,       // an image proposal whose images gave no relative pose (too few inliers, degenerate)
  NoFilter,             // an image proposal in dead reckoning
  LoopClosureDisabled,  // an image proposal with [loop_closure] enabled = false
  NoOverlap,            // nowhere the gate admits could the scans share min_matched_fraction (not aligned)
  Submaps,              // the visits' path submaps align nearly as well elsewhere, or (far) do not align where it puts them
  SceneDepth,           // camera alone: at the estimated distance the shared scene would lie beyond max_scene_depth_m
  Join,                 // a merged session's keyframe put where none of its join's fixes puts it, before they tie it
};
// Its name in loop_closures.csv and in observer events ("" for None).
const char* reasonName(ClosureReason reason);

// What confirmed an accepted closure before it went into the filter.
enum class Confirmation : std::uint8_t {
  None,     // nothing (confirm_window = 0: added at once), or not accepted
  Closure,  // a second closure of the next keyframes agreed with it (GlobalSlam::consistent)
  Camera,   // the two places' images measured the same relative pose as the scans (camera_confirmation)
  Jointly,  // refused by the gate alone, it passed the joint gate with a later closure that agreed with it (joint_gate)
};
// Its name in loop_closures.csv ("" for None).
const char* confirmationName(Confirmation c);

// One loop-closure hypothesis and what became of it (a row of loop_closures.csv).
struct LoopClosureRecord {
  size_t from = 0, to = 0;  // earlier keyframe, current keyframe
  double from_time = 0, to_time = 0;
  double score = 0;  // classifier margin, image normalised score, or alignment matched fraction
  bool accepted = false;
  Proposer detector = Proposer::Pose;                         // which source proposed it
  ClosureReason reason = ClosureReason::None;                 // when not accepted
  common::Pose2 measurement;                                  // aligned relative pose (from -> to)
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();  // as added to the filter
  double rms_m = 0, mahalanobis2 = 0, gate_threshold = 0;
  double free_space_conflict = 0;  // alignment::mutualFreeSpaceConflict at the measurement
  double prior_sigma_m = 0;        // largest std. deviation of the relative position before the closure
  // A camera closure that measured bearing and heading only: its translation's length is the
  // estimate's (CameraClosure.h). Scan alignments and full camera poses measure all three.
  bool bearing_only = false;
  Confirmation confirmed_by = Confirmation::None;
  // The ambiguity restarts were left out: the alignment continues a closure that took them
  // (LoopCloser::tryClose).
  bool restarts_skipped = false;
};

// The relative pose of keyframe `current` from `earlier` that the closure `c` implies, carried
// along both visits by the map's estimate: between(earlier, c.from) ⊕ c.measurement ⊕
// between(c.to, current). Confirmation, camera confirmation and continuation compare with it.
common::Pose2 carriedClosure(const Map& map, const LoopClosureRecord& c, size_t earlier, size_t current);

// A record as the map file holds it (the current format), for the records' spill file.
// PipelineState.cpp.
struct LoopClosureRecordCodec {
  static void write(common::BinaryWriter& w, const LoopClosureRecord& c);
  static LoopClosureRecord read(common::BinaryReader& r);
};
// Every hypothesis of a run, oldest first: millions in a city, so all but the newest wait in a
// spill file (io::SpillLog).
using LoopClosureLog = io::SpillLog<LoopClosureRecord, LoopClosureRecordCodec>;

// Appearance similarity of a pair of keyframes (the laser classifier's margin above its
// decision factor: >= 0 is a detection).
using CandidateScorer = std::function<double(size_t earlier, size_t current)>;

// Who proposed a pair, and with what score: the laser classifier among the keyframes within
// reach, or a detector outside the loop closer (Tree of Words). Pairs proposed by the estimate
// alone ("pose") carry none; their score is the alignment's matched fraction.
struct Detection {
  Proposer detector = Proposer::Laser;
  double score = 0;
};

// A pair to align: the earlier keyframe, and its detection when appearance proposed it.
struct Candidate {
  size_t keyframe = 0;
  std::optional<Detection> detection;
};

class LoopCloser {
 public:
  explicit LoopCloser(const LoopClosureOptions& options);

  // With a scorer, appearance adds candidates when the estimate is too uncertain to pick them.
  void setScorer(CandidateScorer scorer);

  // The final candidate set for keyframe `current` of `map` (its spatial index and estimates).
  // First the max_candidates keyframes nearest the estimate (Mahalanobis). When the pose relative
  // to the nearest keyframe is uncertain beyond appearance_min_sigma_m, many keyframes lie within
  // reach and the nearest ones are as likely wrong as any: they are searched at every
  // far_every_n_keyframes-th keyframe only, and with a scorer up to max_candidates of the
  // classifier's detections follow, best first and one per place (search_radius_m apart).
  // `confirming`: a closure hypothesis waits for its confirmation, which only the next
  // keyframes' searches can bring, so they search at every keyframe.
  std::vector<Candidate> candidates(KeyframeNodes& filter, const Map& map, size_t current, bool confirming = false);
  // Alignment and gating of one candidate. With `commit`, a closure that passes is
  // added to the filter; without, it is only tested (accepted = passed) for later confirmation.
  // `recent`: an accepted closure a few keyframes back that took the ambiguity restarts. An
  // alignment that continues it (continuesClosure) leaves them out: they would test the
  // uniqueness of the minimum that its restarts tested. So along a revisit every other closure
  // takes them, each with its own scans.
  LoopClosureRecord tryClose(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current, bool commit = true,
                             const Detection* detection = nullptr, const LoopClosureRecord* recent = nullptr);
  // Whether `earlier` -> `current` measured as `z` continues the accepted closure `c`: `earlier` is
  // of the same earlier visit (within min_keyframe_gap keyframes of c's), and c, carried along
  // both visits by the estimate, puts `current` where z does, within what the ambiguity restarts
  // count as the same minimum (a quarter of ambiguity_offset_m) and confirm_tolerance_deg.
  bool continuesClosure(const Map& map, const LoopClosureRecord& c, size_t earlier, size_t current, const common::Pose2& z) const;
  // Gating (and with `commit` the update) of a relative-pose factor measured by another sensor
  // in place of a scan alignment. With `camera` (the images that measured it: CameraClosure.h),
  // first the scene's depth: a monocular pair fixes its scene up to the baseline, and at the
  // distance the estimate puts between the cameras it must lie within max_scene_depth_m
  // (nearestSceneDepth; reason SceneDepth, not gated).
  LoopClosureRecord tryCloseMeasured(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current, const esdf::Vec3& z,
                                     const Eigen::Matrix3d& information, bool commit, const Detection& detection,
                                     const CameraMeasurement* camera = nullptr);
  // The same over a filter whose poses are the keyframes, one each.
  std::vector<Candidate> candidates(esdf::Esdf& filter, const Map& map, size_t current, bool confirming = false) {
    KeyframeNodes nodes(filter, false);
    return candidates(nodes, map, current, confirming);
  }
  LoopClosureRecord tryClose(esdf::Esdf& filter, const Map& map, size_t earlier, size_t current, bool commit = true,
                             const Detection* detection = nullptr, const LoopClosureRecord* recent = nullptr) {
    KeyframeNodes nodes(filter, false);
    return tryClose(nodes, map, earlier, current, commit, detection, recent);
  }

  // The checks of a closure that need no estimate, for two scans aligned from `guess` by
  // `method`: the alignment's residual and matched share, the ambiguity restarts as far as
  // reach_m, the free-space test. Fills r's measurement, rms_m, free_space_conflict and (when it
  // fails) reason; returns the alignment, its covariance not scaled yet. A place found with no
  // estimate at all (another session's scan) is checked by this alone. With `admitted` (the
  // relative poses the innovation gate would let in), scans that could not share
  // min_matched_fraction of the current scan's points at any of them are not aligned at all
  // (reason NoOverlap, the alignment not converged).
  alignment::AlignmentResult verifyAlignment(const io::LaserScan& earlier, const io::LaserScan& current, const common::Pose2& guess,
                                             alignment::Method method, double reach_m, LoopClosureRecord& r,
                                             const alignment::PoseRegion* admitted = nullptr) const;
  // The relative covariances kept for the current keyframe (a later image proposal for it
  // reuses them). The scorer is code: whoever set it sets it again.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r);
  // Covariance of the relative pose ⊖x_i ⊕ x_k (conservative), kept for the current keyframe k.
  Eigen::Matrix3d relativeCovariance(KeyframeNodes& filter, size_t i, size_t k);

 private:
  LoopClosureOptions options_;
  CandidateScorer scorer_;
  double chi2_2dof_;
  size_t cached_for_ = static_cast<size_t>(-1);
  std::unordered_map<size_t, Eigen::Matrix3d> cached_;  // relative covariances for cached_for_
  std::optional<bool> narrow_view_;                     // the laser covers well under the full circle (read once)
  size_t current_scan_for_ = static_cast<size_t>(-1);
  const Map* current_scan_map_ = nullptr;
  size_t current_scan_judged_to_ = 0;  // the map's size when current_scan_ was judged
  io::LaserScan current_scan_;  // the current keyframe's scan, its moving returns hidden (staticScan)

  MovingReturns moving_;  // the judges' free space, kept between attempts
  // Keyframe k's scan without the returns that moved (MovingReturns.h), judged by the keyframes
  // around it that the map holds, placed by the estimate (global SLAM seeks a keyframe's
  // closures once the ones after it are in: GlobalSlam::searchLag).
  io::LaserScan staticScan(KeyframeNodes& filter, const Map& map, size_t k);

  // Two scans aligned by verifyAlignment's first step, kept for its ambiguity restarts (which
  // tryClose runs only when the gate does not refuse the closure anyway).
  struct AlignedScans {
    alignment::AlignmentResult result;
    std::unique_ptr<const alignment::IndexedReference> earlier;
    alignment::PointSet current;
    alignment::AlignerOptions options;
    double reach_m = 0;
  };
  // verifyAlignment's steps: the alignment with its residual and matched share (r's measurement,
  // rms_m and, when it fails, reason), then the ambiguity restarts, then the free-space test.
  AlignedScans alignScans(const io::LaserScan& earlier, const io::LaserScan& current, const common::Pose2& guess, alignment::Method method,
                          double reach_m, LoopClosureRecord& r, const alignment::PoseRegion* admitted) const;
  bool ambiguous(const AlignedScans& a) const;
  bool freeSpaceConflict(const io::LaserScan& earlier, const io::LaserScan& current, LoopClosureRecord& r) const;

  // For a candidate heading the other way, the keyframe of its visit whose view meets the current
  // scan's ([loop_closure] opposite_view_offset_m); none when the candidate stays.
  std::optional<size_t> oppositeViewPartner(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current, size_t newest_allowed);
  // Whether the pair (estimates xi, xk) heads more than 90° apart with a laser well short of the
  // full circle (opposite_view_offset_m on): the candidates it changes and the check it adds.
  bool headingOtherWay(const Map& map, const esdf::Vec3& xi, const esdf::Vec3& xk, size_t current);
};

}  // namespace urbanslam::slam
