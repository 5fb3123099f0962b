#pragma once
// Local features of one grayscale image: keypoints and their descriptors (SIFT, as the thesis,
// or ORB as the fast option), capped per image so that a textured frame cannot blow up the
// per-frame time.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "urbanslam/vision_loop/Descriptor.h"

namespace urbanslam::vision_loop {

struct FeatureOptions {
  DescriptorType type = DescriptorType::Sift;
  int max_features = 500;        // strongest responses kept (SIFT: contrast, ORB: Harris score)
  int max_image_side_px = 1024;  // larger images are downscaled first (0: never); wallpapers are 4K
  // Smaller images are upscaled (bicubic) to this longer side before detection (0: never): on a
  // 160x120 image most of the frame lies within ORB's 31-pixel border and SIFT finds few
  // extrema; upscaled, both find features at the finer scales the image does hold.
  int min_image_side_px = 0;
};

struct ImageFeatures {
  std::vector<cv::KeyPoint> keypoints;  // in pixels of the (possibly downscaled) image
  cv::Mat descriptors;                  // CV_8U, one row per keypoint: 128 (SIFT) or 32 (ORB) bytes
  cv::Size image_size;                  // size the keypoints refer to
  size_t size() const { return keypoints.size(); }
};

// Not thread-safe (OpenCV detectors keep scratch buffers): use one extractor per thread.
class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureOptions& options = {});
  // `gray`: 8-bit single channel (colour images are converted).
  ImageFeatures extract(const cv::Mat& image) const;
  const FeatureOptions& options() const { return options_; }

 private:
  FeatureOptions options_;
  cv::Ptr<cv::Feature2D> detector_;
};

}  // namespace urbanslam::vision_loop
