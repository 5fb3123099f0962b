#include "urbanslam/vision_loop/FeatureExtractor.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

FeatureExtractor::FeatureExtractor(const FeatureOptions& options) : options_(options) {
  if (options_.max_features <= 0) throw common::InputError("max_features must be > 0");
  if (options_.type == DescriptorType::Sift) {
    // CV_8U descriptors: OpenCV saturates every component to 0..255 anyway (see Descriptor.h).
    detector_ = cv::SIFT::create(options_.max_features, 3, 0.04, 10, 1.6, CV_8U);
  } else {
    detector_ = cv::ORB::create(options_.max_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  }
}

ImageFeatures FeatureExtractor::extract(const cv::Mat& image) const {
  ImageFeatures f;
  if (image.empty()) return f;
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  else
    gray = image;
  if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U);
  const int side = std::max(gray.cols, gray.rows);
  if (options_.max_image_side_px > 0 && side > options_.max_image_side_px) {
    const double s = static_cast<double>(options_.max_image_side_px) / side;
    cv::Mat small;
    cv::resize(gray, small, cv::Size(), s, s, cv::INTER_AREA);
    gray = small;
  }
  const int side_now = std::max(gray.cols, gray.rows);
  if (options_.min_image_side_px > 0 && side_now > 0 && side_now < options_.min_image_side_px) {
    const double s = static_cast<double>(options_.min_image_side_px) / side_now;
    cv::Mat large;
    cv::resize(gray, large, cv::Size(), s, s, cv::INTER_CUBIC);
    gray = large;
  }
  f.image_size = gray.size();
  detector_->detectAndCompute(gray, cv::noArray(), f.keypoints, f.descriptors);
  // SIFT's cap is applied before orientation assignment and may return a few extra keypoints
  // (one per extra orientation); keep the cap strict so per-frame work is bounded.
  if (static_cast<int>(f.keypoints.size()) > options_.max_features) {
    std::vector<int> order(f.keypoints.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return f.keypoints[a].response > f.keypoints[b].response; });
    order.resize(options_.max_features);
    std::sort(order.begin(), order.end());
    std::vector<cv::KeyPoint> kp;
    cv::Mat d(static_cast<int>(order.size()), f.descriptors.cols, f.descriptors.type());
    for (size_t i = 0; i < order.size(); ++i) {
      kp.push_back(f.keypoints[order[i]]);
      f.descriptors.row(order[i]).copyTo(d.row(static_cast<int>(i)));
    }
    f.keypoints = std::move(kp);
    f.descriptors = d;
  }
  if (f.descriptors.empty()) f.descriptors = cv::Mat(0, descriptorBytes(options_.type), CV_8U);
  if (f.descriptors.type() != CV_8U) f.descriptors.convertTo(f.descriptors, CV_8U);
  return f;
}

}  // namespace urbanslam::vision_loop
