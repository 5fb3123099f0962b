// TUM trajectories: the format evo, the TUM tools and Cartographer's evaluation read.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "TextScanner.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io {

void writeTum(const std::string& path, const std::vector<StampedPose>& unordered) {
  // TUM files are read as time series (evo, the TUM tools, our eval interpolate in them), but
  // logs are not always in time order: the Intel log holds scans whose time is earlier than the
  // scan before them. Every pose is kept (they are all estimates); equal times keep their order.
  std::vector<StampedPose> poses = unordered;
  std::stable_sort(poses.begin(), poses.end(), [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  common::AtomicFile f(path);
  auto& os = f.stream();
  os << "# timestamp x y z qx qy qz qw\n";
  char buf[256];
  for (const auto& p : poses) {
    std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", p.timestamp, p.pose.x, p.pose.y, std::sin(p.pose.phi / 2),
                  std::cos(p.pose.phi / 2));
    os << buf;
  }
  f.commit();
}

std::vector<StampedPose> readTum(const std::string& path) {
  detail::TextScanner t(detail::openGzFile(path), path);
  std::vector<StampedPose> out;
  std::string line;
  std::vector<std::string> f;
  while (t.nextLine(line)) {
    detail::splitFields(line, f);
    if (f.empty() || f[0][0] == '#') continue;
    const std::string where = path + ":" + std::to_string(t.lineNumber());
    if (f.size() != 8) throw common::InputError(where + ": expected 8 fields (timestamp x y z qx qy qz qw)");
    double v[8];
    v[0] = detail::parseNumber(f[0], where, "timestamp");
    for (size_t i = 1; i < 8; ++i) v[i] = detail::parseCoordinate(f[i], where, i < 4 ? "position" : "quaternion component");
    // Yaw of a general quaternion (the 2D part of a 3D trajectory).
    const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
    const double yaw = std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
    out.push_back({v[0], {v[1], v[2], yaw}});
  }
  return out;
}

}  // namespace urbanslam::io
