#include "urbanslam/sim/WallsOutput.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::sim {

WallsSummary writeWalls(const CityModel& city, const std::set<std::pair<int, int>>& tiles, const std::string& csv_path,
                        const std::string& png_path, double resolution_m, int max_pixels_per_side) {
  WallsSummary sum;
  if (tiles.empty()) return sum;
  int tx0 = tiles.begin()->first, tx1 = tx0, ty0 = tiles.begin()->second, ty1 = ty0;
  for (const auto& [tx, ty] : tiles) {
    tx0 = std::min(tx0, tx);
    tx1 = std::max(tx1, tx);
    ty0 = std::min(ty0, ty);
    ty1 = std::max(ty1, ty);
  }
  const double ts = city.tileSize();
  const double x0 = tx0 * ts, y0 = ty0 * ts, w = (tx1 - tx0 + 1) * ts, h = (ty1 - ty0 + 1) * ts;
  const double res = std::max(resolution_m, std::max(w, h) / max_pixels_per_side);
  const int wp = static_cast<int>(std::ceil(w / res)), hp = static_cast<int>(std::ceil(h / res));
  cv::Mat img(hp, wp, CV_8UC1, cv::Scalar(0));
  auto px = [&](Vec2 p) { return cv::Point(static_cast<int>((p.x - x0) / res), hp - 1 - static_cast<int>((p.y - y0) / res)); };

  common::AtomicFile csv(csv_path);
  csv.stream() << "x1,y1,x2,y2\n";
  char buf[128];
  for (const auto& [tx, ty] : tiles) {  // std::set: a fixed order, so the file is reproducible
    const auto t = city.tile(tx, ty);
    for (const Segment& s : t->segments) {
      std::snprintf(buf, sizeof buf, "%.3f,%.3f,%.3f,%.3f\n", s.a.x, s.a.y, s.b.x, s.b.y);
      csv.stream() << buf;
      cv::line(img, px(s.a), px(s.b), cv::Scalar(255), 1, cv::LINE_8);
      ++sum.segments;
    }
  }
  csv.commit();
  common::writeAtomically(png_path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, img)) throw common::InputError(png_path + ": cannot write the image");
  });
  sum.width_px = wp;
  sum.height_px = hp;
  sum.resolution_m = res;
  return sum;
}

}  // namespace urbanslam::sim
