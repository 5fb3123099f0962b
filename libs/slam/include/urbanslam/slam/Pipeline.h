#pragma once
// The main job (thesis §5.5), one measurement at a time, in named stages: odometry → local SLAM
// (motion, keyframe decision, the scan matched against the local submap) → global SLAM (the
// keyframe into the filter, loop closures) → the map. Camera images attach to keyframes and
// feed Tree of Words proposals to global SLAM. Observers see every step.
//
// Local SLAM runs in step(); global SLAM takes its keyframes and images in order, on a thread of
// its own with [estimator] global_thread (a queue between them, so a closure's recovery never
// holds up the sensors), else inline. Local SLAM never reads what global SLAM estimates, so both
// give the same map. Until runInput() or finish() returns, the map is global SLAM's: read it
// through observers.
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "urbanslam/common/SerialWorker.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/SpillLog.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/InputFilter.h"
#include "urbanslam/slam/KeyframeImages.h"
#include "urbanslam/slam/LocalSlam.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/PipelineStats.h"
#include "urbanslam/slam/SessionJoin.h"
#include "urbanslam/vision_loop/BagOfWords.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"

namespace urbanslam::vision_loop {
class LoopDetector;
}

namespace urbanslam::slam {

class Pipeline {
 public:
  explicit Pipeline(PipelineOptions options);
  ~Pipeline();

  // The observer must outlive the pipeline: global SLAM's thread may call it until the pipeline
  // is destroyed (after an error in the reading thread, too).
  void addObserver(PipelineObserver* observer);
  // Processes one measurement. Returns false when the input is exhausted.
  bool step(io::DataSource& source);
  // Runs to the end of the input, then finish().
  void run(io::DataSource& source);
  // Runs to the end of the input without finish(), and waits for global SLAM: a run that saves
  // its map (MapFile.h) saves it here, since finish() drops the hypotheses awaiting confirmation
  // that a continued run still confirms.
  void runInput(io::DataSource& source);
  // Waits until global SLAM has taken everything handed over so far (a filter failure there is
  // reported against `source`).
  void waitForGlobalSlam(const io::DataSource& source);
  // Final full recovery; tells observers the run is complete.
  void finish();
  // finish(), a filter failure reported as bad input against `source` (as run() does).
  void finish(const io::DataSource& source);
  bool finished() const { return finished_; }

  // Everything a continued run depends on, in tagged sections (PipelineState.cpp; the file
  // around it: MapFile.h). readState() goes into a fresh pipeline built with the same options,
  // before any step, and throws common::InputError for contents it cannot take. format_version:
  // the map file's (MapFile.h), which says what the sections hold.
  void writeState(common::BinaryWriter& w) const;
  // `continued`: the pipeline will go on (a map with a Tree of Words database over camera images,
  // which the file does not hold, is refused); false: it is only read (localization).
  void readState(common::BinaryReader& r, std::uint32_t format_version, bool continued = true);

  // Another session's map joined to this one (`join`: SessionJoin.h): its keyframes, scans and
  // odometry constraints appended after this map's, the first tied to this map's keyframe nearest
  // to where the join's transform puts it, each place the join recognised added as a closure,
  // and global SLAM closing loops for each keyframe as a run would, so that both are optimised
  // jointly. The session's local SLAM becomes this pipeline's: a continued run continues the
  // session. Both must have the same options (loadMap checks them). Before finish(), of both.
  // PipelineMerge.cpp.
  void appendSession(const Pipeline& session, const SessionJoin& join);

  // Keyframes made so far by local SLAM (global SLAM may not have taken them all yet).
  size_t keyframesMade() const { return local_.keyframes(); }
  const Map& map() const { return map_; }
  const PerKeyframe<Keyframe>& keyframes() const { return map_.keyframes(); }
  // Estimated pose at every odometry (or drive) reading's time and at every scan placed by
  // matching (scanTrajectory(): at a scan's time this is the scan's pose), from the current
  // keyframe estimates and the odometry between the scans.
  std::vector<io::StampedPose> odometryTrajectory() const { return map_.odometryTrajectory(); }
  // Estimated pose at every scan placed by scan matching: the keyframes and, with
  // [local] match_every_scan, the scans matched between them. Between these the trajectory at
  // odometry times has only the odometry.
  std::vector<io::StampedPose> scanTrajectory() const { return map_.scanTrajectory(); }
  // The log's reference trajectory, when it has one (e.g. a corrected CARMEN log).
  // The log's reference poses (ground truth, the simulator's truth), read back whole.
  std::vector<io::StampedPose> referenceTrajectory() const { return reference_.toVector(); }
  // Every hypothesis and its fate, oldest first; loopClosures() reads them back whole (small
  // runs and tests).
  const LoopClosureLog& loopClosureLog() const { return global_.closureLog(); }
  std::vector<LoopClosureRecord> loopClosures() const { return global_.closures(); }
  // The pose graph's edges read back whole (small runs and tests); map().edges() streams them.
  std::vector<GraphEdge> graphEdges() const { return map_.edges().toVector(); }
  const PipelineStats& stats() const { return stats_; }
  const PipelineOptions& options() const { return options_; }
  std::string estimatorName() const { return slam::estimatorName(options_.estimator.type); }
  std::vector<io::PosedScan> posedKeyframes() const { return map_.posedKeyframes(); }

 private:
  bool stepOnce(io::DataSource& source);
  // Runs `body`, a filter failure (in it or in global SLAM's queue) reported against `source`.
  template <typename Body>
  void reportingFilterFailures(const io::DataSource& source, const std::string& where, Body&& body);
  // Hands `body` to global SLAM; a filter failure in it names the measurement being read now.
  // Returns the job's ticket (SerialWorker::waitFor).
  size_t postToGlobalSlam(std::function<void()> body);
  // Local SLAM takes global SLAM's estimate of the submap as it stood after keyframe
  // k - [local] correction_lag_keyframes, waiting for it if global SLAM is not that far yet.
  void correctSubmap(size_t k);
  // Local SLAM has a submap to correct and a lag to correct it at.
  bool takesSubmapCorrections() const { return options_.local.correction_lag_keyframes > 0 && options_.local.scan_matching; }
  // Waits for global SLAM's queue to run dry; records the most it ever held.
  void drainGlobalSlam();
  void writeStateNow(common::BinaryWriter& w) const;
  void onScan(io::LaserScan scan, double progress);
  // `camera_motion`: the camera's view of the motion since the previous keyframe (camera-only logs).
  void addKeyframe(io::LaserScan scan, const std::optional<CameraMeasurement>& camera_motion = std::nullopt);
  // Camera images (PipelineImages.cpp): attachment to keyframes, Tree of Words proposals, the
  // camera's relative poses.
  struct PreparedImage {
    vision_loop::ImageFeatures features;
    vision_loop::BagOfWords words;
  };
  struct ImageCamera {
    std::optional<io::CameraCalibration> calibration;
    int width = 0;  // of the image the calibration is for
  };
  void startImageDetector();  // [loop_closure] image_detector, at the first image
  void onCameraImage(const io::CameraImage& image, double progress);
  PreparedImage prepareImage(const io::CameraImage& image) const;
  // Hands the image to global SLAM's queue (attachImage there).
  void postImage(AssignedImage assigned, std::optional<PreparedImage> prepared = std::nullopt);
  void attachImage(const AssignedImage& assigned, std::optional<PreparedImage> prepared, SteadyTime handed_over);
  // The camera's relative pose between two images, when both are calibrated (the same camera);
  // invalid when the images give none.
  std::optional<CameraMeasurement> measureCamera(const ImageCamera& a, const vision_loop::ImageFeatures& fa, const ImageCamera& b,
                                                 const vision_loop::ImageFeatures& fb) const;
  // The same closure's full pose (m.metric), when an image next to the earlier one (database ids)
  // gives its features a depth ([image_loop] metric_pose).
  void measureLength(size_t earlier_image, size_t current_image, CameraMeasurement& m);
  // The camera's view of keyframes (earlier, current) for global SLAM's confirmation of closures:
  // the images nearest to them (kImageReachKeyframes), measured with their full pose, or nothing.
  // The pairs measured for the current keyframe's candidates are kept (they ask for the same
  // images), until the next keyframe's.
  std::optional<CameraPairView> cameraView(size_t earlier, size_t current);
  std::optional<size_t> nearestImage(size_t keyframe) const;  // its image database id

  PipelineOptions options_;
  std::vector<PipelineObserver*> observers_;
  InputFilter input_;
  struct StampedPoseCodec {
    static void write(common::BinaryWriter& w, const io::StampedPose& p);
    static io::StampedPose read(common::BinaryReader& r);
  };
  // One per reference reading, read only for the outputs: all but the newest in a spill file.
  io::SpillLog<io::StampedPose, StampedPoseCodec> reference_;
  PipelineStats stats_;
  Map map_;
  LocalSlam local_;
  GlobalSlam global_;
  std::unique_ptr<vision_loop::LoopDetector> image_detector_;  // [loop_closure] image_detector = tree_of_words
  std::vector<size_t> image_keyframes_;                        // image database id -> keyframe
  std::vector<ImageCamera> image_cameras_;                     // image database id -> its camera
  KeyframeImageAssigner images_;
  // (image, image) -> view, for the current keyframe's candidates (a few pairs)
  std::vector<std::pair<std::pair<size_t, size_t>, std::optional<CameraPairView>>> camera_views_;
  SubmapCorrections submap_corrections_;
  std::deque<std::pair<size_t, size_t>> keyframe_tickets_;  // keyframe -> its global SLAM job's ticket
  bool have_first_ts_ = false;
  bool finished_ = false;
  // Last: it stops before what its jobs use goes away. Mutable: reading the state waits for it.
  mutable common::SerialWorker global_worker_;
};

}  // namespace urbanslam::slam
