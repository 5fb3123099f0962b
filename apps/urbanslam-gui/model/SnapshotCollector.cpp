#include "SnapshotCollector.h"

namespace urbanslam::gui {

void SnapshotCollector::onKeyframe(const slam::KeyframeEvent& e) {
  // Converting the scan to points happens outside the lock.
  auto pts = std::make_shared<const std::vector<io::Point2>>(io::scanToPoints(*e.scan, true));
  std::lock_guard<std::mutex> lock(mutex_);
  state_.keyframes.push_back({e.index, e.timestamp, e.pose, std::move(pts), nullptr});
  state_.current_covariance = e.covariance;
  state_.stats.keyframes = state_.keyframes.size();
  ++state_.version;
}

void SnapshotCollector::onPosesUpdated(const slam::PosesUpdatedEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (size_t i = 0; i < e.poses->size() && i < state_.keyframes.size(); ++i) state_.keyframes[i].pose = (*e.poses)[i];
  ++state_.version;
}

void SnapshotCollector::onCandidates(const slam::CandidatesEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_.candidates = *e.candidates;
  ++state_.version;
}

void SnapshotCollector::onLoopClosure(const slam::LoopClosureEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_.closures.push_back(e);
  if (e.detector == slam::Proposer::Image) {
    // The final fate of a proposal that was waiting for a confirming closure.
    for (auto it = state_.image_matches.rbegin(); it != state_.image_matches.rend(); ++it)
      if (it->current == e.to_keyframe && it->matched == e.from_keyframe) {
        it->accepted = e.accepted;
        it->fate = e.accepted ? "accepted" : e.reason;
        break;
      }
  }
  (e.accepted ? state_.stats.closures_accepted : state_.stats.closures_rejected)++;
  ++state_.version;
}

void SnapshotCollector::onImage(const io::CameraImage& image) {
  auto copy = std::make_shared<const io::CameraImage>(image);
  std::lock_guard<std::mutex> lock(mutex_);
  state_.last_image = std::move(copy);
  ++state_.version;
}

void SnapshotCollector::onKeyframeImage(const slam::KeyframeImageEvent& e) {
  // A copy of the small header; the pixels stay in the shared buffer.
  auto image = std::make_shared<const io::CameraImage>(*e.image);
  std::lock_guard<std::mutex> lock(mutex_);
  if (e.keyframe < state_.keyframes.size() && state_.keyframes[e.keyframe].index == e.keyframe) {
    state_.keyframes[e.keyframe].image = std::move(image);
    ++state_.version;
  }
}

void SnapshotCollector::onImageMatch(const slam::ImageMatchEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_.image_matches.push_back({e.current_keyframe, e.matched_keyframe, e.score, e.accepted, e.fate});
  ++state_.version;
}

void SnapshotCollector::onStep(const slam::StepEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& s = state_.stats;
  if (first_timestamp_ < 0) first_timestamp_ = e.timestamp;
  s.scans = e.scans;
  s.addStep(e.timestamp - first_timestamp_, e.step_ms, e.progress);
  ++state_.version;
}

void SnapshotCollector::onFinished() {
  std::lock_guard<std::mutex> lock(mutex_);
  state_.finished = true;
  state_.stats.progress = 1.0;
  ++state_.version;
}

MapSnapshot SnapshotCollector::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

size_t SnapshotCollector::version() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_.version;
}

void SnapshotCollector::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t v = state_.version;
  state_ = MapSnapshot{};
  state_.version = v + 1;
  first_timestamp_ = -1;
}

}  // namespace urbanslam::gui
