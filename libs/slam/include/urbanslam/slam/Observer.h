#pragma once
// What the pipeline reports while it runs. The CLI (progress, stats) and the GUI subscribe;
// the library never knows who listens. Callbacks run on the pipeline's thread and must be
// quick: a GUI copies what it needs and redraws on its own thread.
#include <cstddef>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::slam {

struct KeyframeEvent {
  size_t index = 0;             // keyframe id (0-based, in creation order)
  double timestamp = 0;
  common::Pose2 pose;           // current estimate of the vehicle pose
  const io::LaserScan* scan = nullptr;  // valid during the callback (the pipeline keeps it)
};

struct StepEvent {
  size_t scans = 0;             // laser scans processed so far
  size_t keyframes = 0;
  double timestamp = 0;         // of the last measurement
  double step_ms = 0;           // processing time of this scan
  double progress = 0;          // fraction of the input read, [0,1]
};

class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void onKeyframe(const KeyframeEvent&) {}
  virtual void onStep(const StepEvent&) {}
  virtual void onFinished() {}
};

}  // namespace urbanslam::slam
