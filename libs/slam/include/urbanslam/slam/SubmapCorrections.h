#pragma once
// Global SLAM's estimate of the local submap, handed back to local SLAM a fixed number of
// keyframes late. Local SLAM matches in its own frame, the chain of the constraints it handed
// on; without this, loop closures never reach that chain, and where the closures keep
// correcting the recent path (a park of trees seen again and again) the submap keeps the
// odometry's bends. Taking global SLAM's estimate as it stood right after a given keyframe's
// job, never whatever it holds at the moment, keeps a run's results independent of when
// global SLAM gets to its work: the front end waits only when global SLAM is more than the lag
// behind.
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Pose2.h"

namespace urbanslam::slam {

struct SubmapEstimate {
  size_t keyframe = 0;                // the newest keyframe global SLAM had taken
  std::vector<common::Pose2> poses;  // of keyframes keyframe - poses.size() + 1 ... keyframe
};

// Written by global SLAM's thread, read by local SLAM's: every call locks.
class SubmapCorrections {
 public:
  void publish(SubmapEstimate estimate);
  // The estimate published after `keyframe`, if it has been; older ones are dropped.
  std::optional<SubmapEstimate> take(size_t keyframe);

  // The estimates not taken yet (a continued run takes them as the whole run would).
  // PipelineState.cpp.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r);

 private:
  mutable std::mutex mutex_;
  std::deque<SubmapEstimate> published_;
};

}  // namespace urbanslam::slam
