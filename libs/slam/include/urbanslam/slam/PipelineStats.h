#pragma once
// What a run counts and times, reported in stats.json.
#include <cstddef>
#include <vector>

#include "urbanslam/common/DurationHistogram.h"

namespace urbanslam::slam {

struct PipelineStats {
  size_t measurements = 0, scans = 0, scans_used = 0, odometry = 0, drive = 0, images = 0, gps = 0, reference = 0, keyframes = 0;
  size_t scan_matches_used = 0, scan_matches_rejected = 0;
  size_t camera_motions_used = 0, camera_motions_rejected = 0;  // camera-only keyframes: the camera's view of the motion
  size_t scans_anchored = 0;  // scans between keyframes placed by a submap match ([local] match_every_scan)
  size_t closures_tried = 0, closures_accepted = 0, closures_rejected = 0;
  size_t image_keyframes = 0;  // keyframes with an image attached
  size_t image_proposals = 0;  // Tree of Words detections (each also a loop_closures.csv row)
  double first_timestamp = 0, last_timestamp = 0;
  double wall_s = 0;  // processing time, reading included
  // Durations as histograms (percentiles within 1 %, constant memory however long the run).
  common::DurationHistogram step_ms;  // per processed scan
  // The same, by the map's size when the step ran: decade k holds the steps taken with 10^k to
  // 10^(k+1) - 1 keyframes (constant time per step means the same figures in every decade).
  std::vector<common::DurationHistogram> step_ms_by_decade;
  void recordStep(double ms, size_t keyframes);
  common::DurationHistogram keyframe_ms, closure_ms;
  // From local SLAM handing over a keyframe to the map corrected by the closure it brought, per
  // accepted closure (global SLAM's queue included when it runs on its own thread).
  common::DurationHistogram global_latency_ms;
  size_t global_backlog_max = 0;  // most keyframes and images waiting for global SLAM at once
  // Local SLAM waited this long for global SLAM's estimate of the submap ([local]
  // correction_lag_keyframes): global SLAM was further behind than the lag.
  double global_wait_s = 0;
};

}  // namespace urbanslam::slam
