#pragma once
// The main job (thesis §5.5), one scan at a time: motion since the last keyframe → keyframe
// decision → local scan matching → ESDF prediction with augmentation → recovery of the recent
// poses → loop-closure candidates → detection → alignment → innovation gating → ESDF update →
// full recovery after a closure. Observers see every step; the map is rebuilt from the current
// keyframe estimates on demand.
#include <Eigen/Core>
#include <deque>
#include <memory>
#include <vector>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/KeyframeImages.h"
#include "urbanslam/slam/LocalSubmap.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/MotionIntegrator.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/vision_loop/BagOfWords.h"

namespace urbanslam::esdf {
class Esdf;
}
namespace urbanslam::laser_loop {
class LoopDetector;
}
namespace urbanslam::vision_loop {
class LoopDetector;
}

namespace urbanslam::slam {

struct Keyframe {
  size_t index = 0;
  double timestamp = 0;
  common::Pose2 pose;   // current estimate
  io::LaserScan scan;   // kept so the map can be rebuilt from the current estimates; empty
                        // for keyframes made from camera images alone
  bool has_image = false;              // an image was attached (nearest in time)
  vision_loop::BagOfWords image_words;  // its Tree of Words vector (tree_of_words only); no pixels
  bool hasScan() const { return !scan.ranges.empty(); }
};

// A constraint between two keyframes as it went into the filter (for the g2o output).
struct GraphEdge {
  size_t from = 0, to = 0;
  common::Pose2 measurement;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
  bool loop_closure = false;
};

struct PipelineStats {
  size_t measurements = 0, scans = 0, scans_used = 0, odometry = 0, drive = 0, images = 0, gps = 0,
         reference = 0, keyframes = 0;
  size_t scan_matches_used = 0, scan_matches_rejected = 0;
  size_t scans_anchored = 0;     // scans between keyframes placed by a submap match ([local] match_every_scan)
  size_t closures_tried = 0, closures_accepted = 0, closures_rejected = 0;
  size_t image_keyframes = 0;   // keyframes with an image attached
  size_t image_proposals = 0;   // Tree of Words detections (each also a loop_closures.csv row)
  double first_timestamp = 0, last_timestamp = 0;
  double wall_s = 0;             // processing time, reading included
  std::vector<double> step_ms;   // per processed scan
  // The same, by the map's size when the step ran: decade k holds the steps taken with 10^k to
  // 10^(k+1) - 1 keyframes (constant time per step means the same figures in every decade).
  std::vector<std::vector<double>> step_ms_by_decade;
  void recordStep(double ms, size_t keyframes);
  std::vector<double> keyframe_ms, closure_ms;
};

class Pipeline {
 public:
  explicit Pipeline(PipelineOptions options);
  ~Pipeline();

  void addObserver(PipelineObserver* observer);
  // An appearance test for loop-closure candidates (the laser classifier); without one every
  // candidate goes to alignment and gating.
  void setCandidateScorer(CandidateScorer scorer, std::string name);
  // Processes one measurement. Returns false when the input is exhausted.
  bool step(io::DataSource& source);
  // Runs to the end of the input, then finish().
  void run(io::DataSource& source);
  // Final full recovery; tells observers the run is complete.
  void finish();

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  // Estimated pose at every odometry (or drive) reading's time and at every scan placed by
  // matching (scanTrajectory(): at a scan's time this is the scan's pose), from the current
  // keyframe estimates and the odometry between the scans.
  std::vector<io::StampedPose> odometryTrajectory() const;
  // Estimated pose at every scan placed by scan matching: the keyframes and, with
  // [local] match_every_scan, the scans matched between them. Between these the trajectory at
  // odometry times has only the odometry.
  std::vector<io::StampedPose> scanTrajectory() const;
  // The log's reference trajectory, when it has one (e.g. a corrected CARMEN log).
  const std::vector<io::StampedPose>& referenceTrajectory() const { return reference_; }
  const std::vector<LoopClosureRecord>& loopClosures() const { return closures_; }
  const std::vector<GraphEdge>& graphEdges() const { return edges_; }
  const PipelineStats& stats() const { return stats_; }
  const PipelineOptions& options() const { return options_; }
  std::string estimatorName() const { return options_.estimator.type; }
  std::vector<io::PosedScan> posedKeyframes() const;

 private:
  // A scan whose pose is known relative to a keyframe: every keyframe (offset identity) and,
  // with [local] match_every_scan, the scans between keyframes that matched the local submap.
  // The trajectory between keyframes is spread between anchors, so it follows the scans
  // (0.2 s apart on FR079) rather than the odometry alone.
  struct ScanAnchor {
    double timestamp;
    size_t keyframe;        // the keyframe it hangs from
    common::Pose2 offset;   // its pose in that keyframe's frame
    common::Pose2 odom;     // odometry pose at its time
  };
  struct OdometrySample {
    double timestamp;
    common::Pose2 odom;   // odometry pose at the reading
    size_t anchor;        // last anchor before it (npos: none yet)
  };
  bool stepOnce(io::DataSource& source);
  void onScan(io::LaserScan scan, double progress);
  void addKeyframe(io::LaserScan scan);
  void localScanMatching(const io::LaserScan& scan, common::Pose2& z, Eigen::Matrix3d& cov);
  // The scan matched with the local submap from the odometry since the last keyframe (prior z
  // with covariance cov): its pose in the last keyframe's frame and the posterior covariance.
  alignment::PriorMatchResult matchSubmap(const io::LaserScan& scan, const common::Pose2& z, const Eigen::Matrix3d& cov) const;
  void anchorScan(const io::LaserScan& scan);
  void addAnchor(const ScanAnchor& anchor);
  void searchLoopClosures(size_t current);
  // Camera images (PipelineImages.cpp): attachment to keyframes, Tree of Words proposals.
  void startImageDetector();  // [loop_closure] image_detector, at the first image
  void onCameraImage(const io::CameraImage& image, double progress);
  void attachImage(const AssignedImage& assigned);
  void proposeImageClosure(size_t earlier, size_t current, double score);
  // A verified hypothesis (passed alignment and gating, or not) through the confirmation step.
  enum class Admission { Rejected, Pending, Accepted };
  Admission admit(LoopClosureRecord r, size_t current);
  void expirePending(size_t current);
  void reportClosure(const LoopClosureRecord& r);
  bool consistent(const LoopClosureRecord& a, const LoopClosureRecord& b) const;
  void recoverAll();
  bool acceptLabel(const std::string& label) const;
  void applyRangeLimits(io::LaserScan& scan) const;
  common::Pose2 currentPose() const;

  PipelineOptions options_;
  std::vector<PipelineObserver*> observers_;
  std::vector<Keyframe> keyframes_;
  std::vector<OdometrySample> odometry_;
  std::vector<ScanAnchor> anchors_;
  std::vector<io::StampedPose> reference_;
  std::vector<LoopClosureRecord> closures_;
  std::vector<GraphEdge> edges_;
  std::vector<std::string> labels_;
  PipelineStats stats_;
  MotionIntegrator motion_;
  std::unique_ptr<esdf::Esdf> esdf_;
  std::unique_ptr<laser_loop::LoopDetector> laser_detector_;  // [loop_closure] detector = laser
  std::unique_ptr<vision_loop::LoopDetector> image_detector_; // [loop_closure] image_detector = tree_of_words
  std::vector<size_t> image_keyframes_;  // image database id -> keyframe
  KeyframeImageAssigner images_;
  std::deque<LoopClosureRecord> pending_;  // passed alignment + gate, awaiting confirmation
  LocalSubmap submap_;
  LoopCloser closer_;
  bool have_first_ts_ = false;
  bool have_scan_keyframe_ = false;  // camera-only logs make a keyframe of every image until a scan comes
  bool dirty_since_recovery_ = false;
};

}  // namespace urbanslam::slam
