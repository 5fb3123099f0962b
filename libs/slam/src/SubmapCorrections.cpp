#include "urbanslam/slam/SubmapCorrections.h"

namespace urbanslam::slam {

void SubmapCorrections::publish(SubmapEstimate estimate) {
  std::lock_guard<std::mutex> lock(mutex_);
  published_.push_back(std::move(estimate));
}

std::optional<SubmapEstimate> SubmapCorrections::take(size_t keyframe) {
  std::lock_guard<std::mutex> lock(mutex_);
  while (!published_.empty() && published_.front().keyframe < keyframe) published_.pop_front();
  if (published_.empty() || published_.front().keyframe != keyframe) return std::nullopt;
  SubmapEstimate e = std::move(published_.front());
  published_.pop_front();
  return e;
}

}  // namespace urbanslam::slam
