#pragma once
// Global SLAM (thesis ch. 5): the one place that changes the filter. A new keyframe enters as a
// delayed pose (ESDF prediction with augmentation, constant time) with local SLAM's constraint;
// then the loop-closure candidates (near the estimate, Mahalanobis-gated; with the laser
// classifier's detections too where the estimate is too uncertain), alignment, the innovation
// gate, confirmation (by a second agreeing closure, or with a camera by the images of the two
// places), the update, and the recovery after it. Tree of Words proposals take the same path from
// the alignment on.
#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "urbanslam/slam/CameraClosure.h"
#include "urbanslam/slam/LocalSlam.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/PipelineStats.h"

namespace urbanslam::laser_loop {
class LoopDetector;
}

namespace urbanslam::slam {

using SteadyTime = std::chrono::steady_clock::time_point;

// The camera's view of a pair of keyframes: the keyframes of the images nearest to them (the
// estimate carries a closure between the pair to these), and the images' relative pose.
struct CameraPairView {
  size_t earlier = 0, current = 0;
  CameraMeasurement camera;
};
// Measures the camera's view of the pair (earlier, current), or nothing when no images near both
// can (no camera, no nearby image, too few matches).
using CameraPairMeasurer = std::function<std::optional<CameraPairView>(size_t earlier, size_t current)>;

class GlobalSlam {
 public:
  // Reports closures and corrected poses to `observers` and counts them in `stats` (both owned
  // by the caller and outliving this).
  GlobalSlam(const PipelineOptions& options, Map& map, PipelineStats& stats, const std::vector<PipelineObserver*>& observers);
  ~GlobalSlam();

  // The keyframe joins the map with the constraint from the previous one. Returns its marginal
  // covariance (row-major; zero without a filter or for the first keyframe).
  std::array<double, 9> addKeyframe(Keyframe kf, io::CompactScan scan, const KeyframeConstraint& constraint);
  // The same with the constraint from keyframe `from` (the first keyframe of a session joined to
  // the map: Pipeline::appendSession).
  std::array<double, 9> addKeyframeFrom(size_t from, Keyframe kf, io::CompactScan scan, const KeyframeConstraint& constraint);
  // Keyframe `newest` is in the map: loop closures with earlier keyframes of every keyframe up to
  // `newest` not yet searched, in order, each when [loop_closure] asks for it then; one whose
  // scan may hold something moving ahead (seesThroughEarlier) stops the search until
  // searchLag() keyframes follow it. `handed_over`: when local SLAM handed `newest` over, for
  // the correction's latency.
  void closeLoops(size_t newest, SteadyTime handed_over);
  // The keyframes still waiting for their search searched now, judged by the keyframes the map
  // holds: at the end of the input, and before another session's keyframes follow this map's.
  void closePendingLoops(SteadyTime handed_over);
  // While a merged session hangs from its join only (Pipeline::appendSession): a closure this
  // says puts the session's keyframe elsewhere than the join does is refused (reason Join).
  // Empty: none.
  void setJoinCheck(std::function<bool(const LoopClosureRecord&)> contradicts_join) { contradicts_join_ = std::move(contradicts_join); }
  // How many keyframes a keyframe's loop closures wait for when its scan sees through where the
  // keyframes before it saw something ([loop_closure] moving_returns_neighbours): the car ahead
  // that moved there, which only later scans see through, would pull its alignments along the
  // street. Any other keyframe is searched at once (closures that land late cost where local
  // SLAM takes the corrected submap). A saved map keeps the keyframes still waiting, so that a
  // continued run searches them as one run over both logs does; finish() searches them.
  size_t searchLag() const;
  // Whether a camera closure between the two keyframes may measure the full pose: where the
  // estimate knows their relative position within [loop_closure] appearance_min_sigma_m (largest
  // sigma), so that a copy of a facade design tens of metres along the street cannot pass the
  // gate with its length (a copy's bearing and heading are the place's own: a bearing-heading
  // closure to it holds). Beyond, bearing and heading only.
  bool allowsFullCameraPose(size_t earlier, size_t current);
  // A Tree of Words proposal between two keyframes, through alignment, gating and confirmation
  // when both have scans, else through gating and confirmation with the camera's relative pose
  // (`camera`: when both images are calibrated; invalid when the images gave none); otherwise
  // recorded with the reason it cannot be. Observers hear its fate.
  void proposeImageClosure(size_t earlier, size_t current, double score, const std::optional<CameraMeasurement>& camera,
                           SteadyTime handed_over);
  // A place that a session join recognised: keyframe `current` (the session's) found at `z` from
  // the map's keyframe `earlier`. Gated and, when it passes, a closure (`detector`: Place for
  // the place search, Laser for the classifier's detection aligned); the fixes that agree with
  // it are its confirmation. A place search's fix is measured by the two keyframes' scans aligned
  // from it where they align (CRF-match and ICP, weighed as a loop closure weighs an alignment),
  // as it is given where they do not.
  void addPlaceFix(size_t earlier, size_t current, const common::Pose2& z, const Eigen::Matrix3d& information, double score,
                   Proposer detector);
  // How closures the scans measured are confirmed by the camera ([loop_closure]
  // camera_confirmation); without it, only by a second closure.
  void setCameraMeasurer(CameraPairMeasurer measurer) { camera_measurer_ = std::move(measurer); }
  // End of input: the last keyframes' loop closures sought, hypotheses still awaiting
  // confirmation dropped, the last poses recovered.
  void finish();

  const LoopClosureLog& closureLog() const { return closures_; }
  // Every record read back whole (small runs and tests).
  std::vector<LoopClosureRecord> closures() const { return closures_.toVector(); }

  // Closure records, hypotheses awaiting confirmation, the loop closer's cache and whether a
  // full recovery is owed. Read after the map: the laser detector's keyframe features are
  // recomputed from the map's scans. PipelineState.cpp.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r, std::uint32_t format_version);

 private:
  enum class Admission { Rejected, Pending, Accepted };
  // What measured a hypothesis: the scans (the camera may confirm it), or the camera itself.
  enum class MeasuredBy { Scans, Camera };
  // A hypothesis's fate: confirmed by an earlier one that agrees with it, or, measured by the
  // scans, by the camera's view (`view`, when the caller measured it: an image proposal; else the
  // measurer's), then gated again and added; else kept waiting for confirmation (4 x
  // confirm_window at most: beyond, unconfirmed at once).
  Admission admit(LoopClosureRecord r, size_t current, MeasuredBy measured = MeasuredBy::Scans,
                  const std::optional<CameraPairView>& view = std::nullopt);
  // Whether the loop closer adds an accepted closure to the filter itself (no confirmation, and
  // no join check that admit() must pass first), or leaves that to admit().
  bool closerCommits() const;
  Admission commit(std::initializer_list<LoopClosureRecord*> records);
  // A closure the gate refused by less than two closures' quantile ([loop_closure] joint_gate):
  // in with an earlier such one that agrees and passes the joint gate, else waiting as pending.
  bool waitsForJointGate(const LoopClosureRecord& r) const;
  Admission admitJointly(LoopClosureRecord r, size_t current);
  // A hypothesis that waited in vain, reported with its reason.
  void reportExpired(LoopClosureRecord r);
  // A hypothesis that passed the gate waits for its confirmation (the candidate search then
  // looks near at every keyframe).
  bool confirming() const;
  // The last accepted closure when it took the ambiguity restarts and is at most confirm_window
  // keyframes (at least one) older than `current`: a closure that continues it leaves them out
  // (LoopCloser::tryClose).
  const LoopClosureRecord* recentClosure(size_t current) const;
  // last_accepted_ becomes `r` when r is accepted and of the newest keyframe so far (as reported,
  // and as a resumed run reads the closures' log).
  void keepIfNewestAccepted(const LoopClosureRecord& r);
  bool cameraConfirms(const LoopClosureRecord& r, const std::optional<CameraPairView>& given) const;
  void expirePending(size_t current);
  bool consistent(const LoopClosureRecord& a, const LoopClosureRecord& b) const;
  // Two measurements of one relative pose agree: within confirm_tolerance_m and _deg.
  bool agree(const common::Pose2& a, const common::Pose2& b) const;
  void reportClosure(const LoopClosureRecord& r);
  // After an accepted closure of keyframe `current`: a full recovery when the map has grown
  // enough since the last one ([estimator] full_recovery_min_growth), else the recent poses.
  // Then also a full recovery when the recovered mean still misses a closure just added by more
  // than the gate (the window could not take up its correction).
  void closureAdded(size_t current, SteadyTime handed_over);
  bool missesAddedClosure() const;
  // Candidates, alignment, gating and confirmation for keyframe `current` (every
  // [loop_closure] every_n_keyframes; along a revisit every revisit_every_n_keyframes).
  void searchLoopsEvery(size_t current, SteadyTime handed_over);
  bool alongRevisit(size_t current) const;
  void searchLoops(size_t current, SteadyTime handed_over);
  // The newest filter poses recovered ([estimator] recent_window), the newest keyframes' poses
  // pulled.
  void recoverRecent();
  // Full recovery: the factors the last one moved relinearised, then [estimator]
  // full_recovery_steps Gauss-Newton steps or (`converge`, the run's last) steps until nothing
  // moves; the latency of the oldest closure it brings into the whole map is recorded.
  void recoverAll(bool converge);
  // The laser classifier with the features of every keyframe so far.
  laser_loop::LoopDetector& laserDetector();

  const PipelineOptions& options_;
  Map& map_;
  PipelineStats& stats_;
  const std::vector<PipelineObserver*>& observers_;
  LoopCloser closer_;
  std::unique_ptr<laser_loop::LoopDetector> laser_detector_;  // [loop_closure] detector = laser, once read
  // Passed alignment and gate, awaiting confirmation (accepted), or refused by the gate alone,
  // awaiting a joint gate (not accepted).
  std::deque<LoopClosureRecord> pending_;
  CameraPairMeasurer camera_measurer_;
  LoopClosureLog closures_;  // every hypothesis and its fate
  bool dirty_since_recovery_ = false;
  size_t last_full_size_ = 0;  // keyframes at the last full recovery
  // The accepted closure of the newest keyframe (a resumed run reads it off the closures' log).
  std::optional<LoopClosureRecord> last_accepted_;
  // The first closure since the last full recovery: its keyframe and when local SLAM handed
  // that over (not saved: a resumed run has no clock of the earlier one's).
  std::optional<std::pair<size_t, SteadyTime>> unrecovered_closure_;
  // The first keyframe whose loop closures have not been sought, and the keyframes from there on
  // that wait for searchLag() keyframes after them (seesThroughEarlier), oldest first.
  size_t next_search_ = 0;
  std::deque<size_t> waiting_;
  // The closures accepted since the last closureAdded (not saved: a checkpoint falls between steps).
  std::vector<LoopClosureRecord> added_;
  std::function<bool(const LoopClosureRecord&)> contradicts_join_;  // setJoinCheck
};

}  // namespace urbanslam::slam
