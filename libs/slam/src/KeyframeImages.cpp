#include "urbanslam/slam/KeyframeImages.h"

#include <cmath>

namespace urbanslam::slam {

void KeyframeImageAssigner::addImage(const io::CameraImage& image) {
  if (open_ && image.timestamp >= open_->time && !open_->after) open_->after = image;
  latest_ = image;
}

// The open keyframe's final image: the nearer of its two neighbours in time, if within the offset
// and not nearer to the next keyframe (`next_time`, when there is one).
std::optional<AssignedImage> KeyframeImageAssigner::close() {
  std::optional<AssignedImage> done;
  if (!open_) return done;
  const double t = open_->time;
  const io::CameraImage* best = nullptr;
  for (const auto* c : {&open_->before, &open_->after})
    if (*c && std::abs((*c)->timestamp - t) <= max_offset_s_ && (!best || std::abs((*c)->timestamp - t) < std::abs(best->timestamp - t)))
      best = &**c;
  if (best) done = AssignedImage{open_->keyframe, *best};
  return done;
}

std::optional<AssignedImage> KeyframeImageAssigner::keyframeAdded(size_t index, double t) {
  // The first image after the open keyframe belongs to the new one when it is strictly nearer.
  if (open_ && open_->after && std::abs(t - open_->after->timestamp) < std::abs(open_->after->timestamp - open_->time))
    open_->after.reset();
  std::optional<AssignedImage> done = close();
  const bool latest_taken = done && latest_ && done->image.timestamp == latest_->timestamp;
  if (open_) previous_time_ = open_->time;
  open_ = Slot{index, t, std::nullopt, std::nullopt};
  // The last image before the new keyframe is its candidate unless the previous keyframe took it
  // or is strictly nearer to it.
  if (latest_ && !latest_taken && latest_->timestamp <= t &&
      (!previous_time_ || std::abs(t - latest_->timestamp) < std::abs(latest_->timestamp - *previous_time_)))
    open_->before = latest_;
  latest_.reset();
  return done;
}

AssignedImage KeyframeImageAssigner::imageKeyframe(size_t index, const io::CameraImage& image) {
  open_.reset();
  previous_time_.reset();
  latest_.reset();
  return {index, image};
}

std::optional<AssignedImage> KeyframeImageAssigner::finish() {
  std::optional<AssignedImage> done = close();
  open_.reset();
  latest_.reset();
  return done;
}

}  // namespace urbanslam::slam
