#pragma once
// Minimal line plots as PNG (no plotting library in the dependency set): axes with tick labels,
// one polyline per series, a legend. Used for the ROC and cross-validation figures; the numbers
// themselves always go to CSV beside the PNG.
#include <string>
#include <vector>

namespace urbanslam::laser_loop {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  int color_bgr = 0x000000;  // 0xBBGGRR
};

struct PlotPanel {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  bool log_x = false;                                   // for ROC curves at small false-alarm rates
  double x_min = 0, x_max = -1, y_min = 0, y_max = -1;  // max < min: from the data
};

// Panels side by side in one image (e.g. Figure 3.5's FA / MD / total). Written atomically.
// Throws common::InputError when the image cannot be written.
void writePlotPng(const std::string& path, const std::vector<PlotPanel>& panels);

}  // namespace urbanslam::laser_loop
