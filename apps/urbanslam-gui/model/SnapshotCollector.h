#pragma once
// Subscribes to the pipeline and keeps the latest MapSnapshot. The pipeline thread writes under
// a mutex for microseconds; the GUI thread takes a copy at most ~20 times a second, so neither
// blocks the other.
#include <mutex>

#include "MapSnapshot.h"
#include "urbanslam/slam/Observer.h"

namespace urbanslam::gui {

class SnapshotCollector : public slam::PipelineObserver {
 public:
  void onKeyframe(const slam::KeyframeEvent& e) override;
  void onPosesUpdated(const slam::PosesUpdatedEvent& e) override;
  void onCandidates(const slam::CandidatesEvent& e) override;
  void onLoopClosure(const slam::LoopClosureEvent& e) override;
  void onImage(const io::CameraImage& image) override;
  void onKeyframeImage(const slam::KeyframeImageEvent& e) override;
  void onImageMatch(const slam::ImageMatchEvent& e) override;
  void onStep(const slam::StepEvent& e) override;
  void onFinished() override;

  // A copy of the current state.
  MapSnapshot snapshot() const;
  size_t version() const;
  void clear();

 private:
  mutable std::mutex mutex_;
  MapSnapshot state_;
  double first_timestamp_ = -1;
};

}  // namespace urbanslam::gui
