#pragma once
// What the pipeline reports while it runs. The CLI (progress, stats) and the GUI subscribe;
// the library never knows who listens. Callbacks must be quick: a GUI copies what it needs and
// redraws on its own thread. onStep and onImage come from the thread that calls
// Pipeline::step; the others from global SLAM, which may run on a thread of its own
// ([estimator] global_thread): an observer of both guards its state with a mutex.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/Proposer.h"

namespace urbanslam::slam {

struct KeyframeEvent {
  size_t index = 0;  // keyframe id (0-based, in creation order)
  double timestamp = 0;
  common::Pose2 pose;  // current estimate of the vehicle pose
  // Marginal covariance of (x, y, phi), row-major; all zero when the estimator has none
  // (dead reckoning).
  std::array<double, 9> covariance{};
  const io::LaserScan* scan = nullptr;  // valid during the callback (the pipeline keeps it)
};

// The estimates of earlier keyframes changed (after a loop closure): poses[i] is keyframe i.
struct PosesUpdatedEvent {
  const std::vector<common::Pose2>* poses = nullptr;
  // The keyframe whose closure brought the correction (none at the end of the run) and how long
  // after local SLAM handed it over the corrected map was ready.
  size_t keyframe = static_cast<size_t>(-1);
  double latency_ms = 0;
  // How long the full recovery that produced these poses took (its share of global SLAM's time
  // grows with the map, which is what a long run's observer watches).
  double recovery_ms = 0;
  // Factorisations of the whole map so far (recoveries and exact covariances).
  long long map_factorisations = 0;
  // Poses in the filter: one per keyframe, fewer where keyframes hang from others'.
  int filter_poses = 0;
};

// A loop-closure hypothesis between the current keyframe and an earlier one, and its fate.
struct LoopClosureEvent {
  size_t from_keyframe = 0, to_keyframe = 0;  // earlier, current
  double timestamp = 0;
  Proposer detector = Proposer::Pose;  // which source proposed it
  double score = 0;
  bool accepted = false;
  std::string reason;  // why rejected: reasonName() of slam::ClosureReason (LoopCloser.h); empty if accepted
};

// The image chosen for a keyframe (the nearest in time, within [loop_closure]
// image_max_offset_s). The pipeline keeps only the image's words; an observer that wants the
// pixels keeps the shared buffer (image->pixels), which is immutable, instead of copying it.
struct KeyframeImageEvent {
  size_t keyframe = 0;
  const io::CameraImage* image = nullptr;  // valid during the callback
};

// Tree of Words proposed that the image of keyframe `current_keyframe` shows the place of the
// earlier keyframe `matched_keyframe`, and what became of the proposal so far.
struct ImageMatchEvent {
  size_t current_keyframe = 0, matched_keyframe = 0;
  double score = 0;       // normalised score (similarity relative to the previous frame's)
  bool accepted = false;  // the closure went into the filter
  // "accepted"; "pending" (passed alignment and gating, awaiting a confirming closure; the
  // final fate follows as a LoopClosureEvent with detector "image"); else why not: the
  // reasonName() of its slam::ClosureReason.
  std::string fate;
};

struct CandidatesEvent {
  size_t keyframe = 0;  // the current keyframe
  const std::vector<size_t>* candidates = nullptr;
};

struct StepEvent {
  size_t scans = 0;  // laser scans processed so far
  size_t keyframes = 0;
  double timestamp = 0;  // of the last measurement
  double step_ms = 0;    // processing time of this scan
  double progress = 0;   // fraction of the input read, [0,1]
};

class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void onKeyframe(const KeyframeEvent&) {}
  virtual void onPosesUpdated(const PosesUpdatedEvent&) {}
  virtual void onCandidates(const CandidatesEvent&) {}
  virtual void onLoopClosure(const LoopClosureEvent&) {}
  virtual void onImage(const io::CameraImage&) {}
  virtual void onKeyframeImage(const KeyframeImageEvent&) {}
  virtual void onImageMatch(const ImageMatchEvent&) {}
  virtual void onStep(const StepEvent&) {}
  virtual void onFinished() {}
};

}  // namespace urbanslam::slam
