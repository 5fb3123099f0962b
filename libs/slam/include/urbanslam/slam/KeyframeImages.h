#pragma once
// Which camera image belongs to which keyframe. Images and scans come at their own rates; an
// image goes to the keyframe nearest to it in time (within a maximum offset; ties to the earlier
// keyframe), and a keyframe with several such images keeps the nearest. Both sides of a keyframe
// count, so the choice for keyframe k is final only once keyframe k+1 exists (or the input
// ends): the pipeline processes an image one keyframe late. Only the two images that can be a
// keyframe's nearest are held (the last one before it, the first one after), with shared pixel
// buffers, so nothing accumulates while the vehicle stands still.
#include <cstddef>
#include <optional>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/io/Measurements.h"

namespace urbanslam::slam {

struct AssignedImage {
  size_t keyframe = 0;
  io::CameraImage image;
};

class KeyframeImageAssigner {
 public:
  explicit KeyframeImageAssigner(double max_offset_s) : max_offset_s_(max_offset_s) {}

  void addImage(const io::CameraImage& image);
  // Keyframe `index` was made at time `t`: the previous keyframe's image, now final (if it has one).
  std::optional<AssignedImage> keyframeAdded(size_t index, double t);
  // A keyframe made from an image (camera-only logs): the image is its own, at once.
  AssignedImage imageKeyframe(size_t index, const io::CameraImage& image);
  // End of input: the last keyframe's image, if it has one.
  std::optional<AssignedImage> finish();

  // The open keyframe and the images held for it, pixels included (PipelineState.cpp).
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r, size_t keyframes);

 private:
  struct Slot {
    size_t keyframe = 0;
    double time = 0;
    std::optional<io::CameraImage> before, after;  // the last image up to `time`, the first after
  };
  double max_offset_s_;
  std::optional<Slot> open_;               // the newest keyframe, whose image may still change
  std::optional<double> previous_time_;    // the keyframe before it
  std::optional<io::CameraImage> latest_;  // the most recent image since the open keyframe
  std::optional<AssignedImage> close();
};

}  // namespace urbanslam::slam
