#include "urbanslam/laser_loop/LinePlot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::laser_loop {

namespace {

constexpr int kW = 520, kH = 400, kLeft = 70, kRight = 20, kTop = 40, kBottom = 55;

cv::Scalar bgr(int c) { return cv::Scalar(c >> 16 & 255, c >> 8 & 255, c & 255); }

std::string label(double v) {
  char buf[32];
  if (v != 0 && (std::fabs(v) < 1e-2 || std::fabs(v) >= 1e4))
    std::snprintf(buf, sizeof buf, "%.0e", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void drawPanel(cv::Mat& img, int x0, const PlotPanel& p) {
  double xmin = p.x_min, xmax = p.x_max, ymin = p.y_min, ymax = p.y_max;
  auto tx = [&](double x) { return p.log_x ? std::log10(std::max(x, 1e-12)) : x; };
  if (xmax < xmin || ymax < ymin) {
    double ax = 1e300, bx = -1e300, ay = 1e300, by = -1e300;
    for (const auto& s : p.series)
      for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_x && s.x[i] <= 0)) continue;
        ax = std::min(ax, s.x[i]);
        bx = std::max(bx, s.x[i]);
        ay = std::min(ay, s.y[i]);
        by = std::max(by, s.y[i]);
      }
    if (ax > bx) ax = 0, bx = 1, ay = 0, by = 1;
    if (xmax < xmin) xmin = ax, xmax = bx;
    if (ymax < ymin) ymin = std::min(0.0, ay), ymax = by > ymin ? by * 1.05 : ymin + 1;
  }
  double lx0 = tx(xmin), lx1 = tx(xmax);
  if (lx1 <= lx0) lx1 = lx0 + 1;
  if (ymax <= ymin) ymax = ymin + 1;
  const int pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  auto px = [&](double x) { return x0 + kLeft + static_cast<int>(std::lround((tx(x) - lx0) / (lx1 - lx0) * pw)); };
  auto py = [&](double y) { return kTop + ph - static_cast<int>(std::lround((y - ymin) / (ymax - ymin) * ph)); };
  const cv::Scalar black(0, 0, 0), grey(210, 210, 210);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (int k = 0; k <= 4; ++k) {
    const double yv = ymin + (ymax - ymin) * k / 4.0;
    cv::line(img, {x0 + kLeft, py(yv)}, {x0 + kLeft + pw, py(yv)}, grey, 1);
    cv::putText(img, label(yv), {x0 + 5, py(yv) + 4}, font, 0.4, black, 1, cv::LINE_AA);
    const double xv = p.log_x ? std::pow(10.0, lx0 + (lx1 - lx0) * k / 4.0) : xmin + (xmax - xmin) * k / 4.0;
    cv::line(img, {px(xv), kTop}, {px(xv), kTop + ph}, grey, 1);
    cv::putText(img, label(xv), {px(xv) - 15, kTop + ph + 16}, font, 0.4, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {x0 + kLeft, kTop}, {x0 + kLeft + pw, kTop + ph}, black, 1);
  cv::putText(img, p.title, {x0 + kLeft, 25}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(img, p.x_label, {x0 + kLeft + pw / 2 - 40, kH - 12}, font, 0.45, black, 1, cv::LINE_AA);
  cv::putText(img, p.y_label, {x0 + 5, kTop - 8}, font, 0.4, black, 1, cv::LINE_AA);
  int legend_y = kTop + 16;
  const cv::Rect clip(x0 + kLeft, kTop, pw + 1, ph + 1);
  for (const auto& s : p.series) {
    std::vector<cv::Point> pts;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_x && s.x[i] <= 0)) continue;
      cv::Point q(px(s.x[i]), py(s.y[i]));
      q.x = std::clamp(q.x, clip.x, clip.x + clip.width - 1);
      q.y = std::clamp(q.y, clip.y, clip.y + clip.height - 1);
      pts.push_back(q);
    }
    if (pts.size() >= 2)
      cv::polylines(img, pts, false, bgr(s.color_bgr), 2, cv::LINE_AA);
    else if (pts.size() == 1)
      cv::circle(img, pts[0], 3, bgr(s.color_bgr), cv::FILLED);
    if (!s.name.empty()) {
      cv::line(img, {x0 + kLeft + pw - 150, legend_y - 4}, {x0 + kLeft + pw - 125, legend_y - 4}, bgr(s.color_bgr), 2);
      cv::putText(img, s.name, {x0 + kLeft + pw - 120, legend_y}, font, 0.4, black, 1, cv::LINE_AA);
      legend_y += 16;
    }
  }
}

}  // namespace

void writePlotPng(const std::string& path, const std::vector<PlotPanel>& panels) {
  cv::Mat img(kH, kW * static_cast<int>(std::max<size_t>(1, panels.size())), CV_8UC3, cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < panels.size(); ++i) drawPanel(img, static_cast<int>(i) * kW, panels[i]);
  common::writeAtomically(path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, img)) throw common::InputError(path + ": cannot write PNG");
  });
}

}  // namespace urbanslam::laser_loop
