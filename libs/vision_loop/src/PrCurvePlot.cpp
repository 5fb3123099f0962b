// The PR curve as a PNG, drawn with OpenCV primitives (no plotting library in the dependencies).
#include <algorithm>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/vision_loop/LoopEvaluation.h"

namespace urbanslam::vision_loop {

void writePrCurvePng(const std::vector<PrPoint>& curve, const std::string& title, const std::string& path) {
  const int w = 640, h = 520, left = 70, right = 20, top = 50, bottom = 60;
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  const int pw = w - left - right, ph = h - top - bottom;
  auto px = [&](double recall, double precision) {
    return cv::Point(left + static_cast<int>(recall * pw + 0.5), top + static_cast<int>((1 - precision) * ph + 0.5));
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (int i = 0; i <= 10; ++i) {
    const double v = i / 10.0;
    cv::line(img, px(v, 0), px(v, 1), cv::Scalar(225, 225, 225), 1);
    cv::line(img, px(0, v), px(1, v), cv::Scalar(225, 225, 225), 1);
    char label[16];
    std::snprintf(label, sizeof label, "%.1f", v);
    cv::putText(img, label, px(v, 0) + cv::Point(-12, 20), font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cv::putText(img, label, px(0, v) + cv::Point(-32, 4), font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::rectangle(img, px(0, 1), px(1, 0), cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "recall", cv::Point(left + pw / 2 - 25, h - 15), font, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "precision", cv::Point(5, top - 12), font, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, title, cv::Point(left, 25), font, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  // Connected in order of decreasing threshold: the curve a user walks by lowering α (recall
  // need not grow monotonically: islands and temporal consistency change with α).
  std::vector<PrPoint> pts = curve;
  std::sort(pts.begin(), pts.end(), [](const PrPoint& a, const PrPoint& b) { return a.threshold > b.threshold; });
  for (size_t i = 1; i < pts.size(); ++i)
    cv::line(img, px(pts[i - 1].recall, pts[i - 1].precision), px(pts[i].recall, pts[i].precision), cv::Scalar(200, 80, 0), 2, cv::LINE_AA);
  for (const auto& p : pts) cv::circle(img, px(p.recall, p.precision), 3, cv::Scalar(200, 80, 0), -1, cv::LINE_AA);
  common::writeAtomically(path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, img)) throw common::InputError(path + ": cannot write PNG");
  });
}

}  // namespace urbanslam::vision_loop
