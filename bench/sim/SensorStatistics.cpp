// sensor_statistics LOG [--laser-labels L] [--max-range M]: the statistics a simulator must
// reproduce, measured the same way on any log (real or simulated), as one JSON object:
//  * odometry: consecutive keyframes (every 1 m or 15 deg of odometry) are aligned by PL-ICP
//    from the odometry increment; where the match is good (most points matched), the odometry
//    increment's error against it: along-track error per metre travelled (a scale error), cross-
//    track error per metre, heading error per metre and per radian turned (rms and median);
//  * laser: PL-ICP's rms point-to-line residual (range noise + surface roughness), the share of
//    beams without a return, and the median range of the returns.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/io/DataSource.h"

using namespace urbanslam;

namespace {

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? 0 : std::sqrt(s / static_cast<double>(v.size()));
}

double medianAbs(std::vector<double> v) {
  for (double& x : v) x = std::abs(x);
  return common::percentile(std::move(v), 50);
}

common::Json summary(const std::vector<double>& v) {
  common::Json j = common::Json::object();
  j["n"] = v.size();
  j["rms"] = rms(v);
  j["median_abs"] = medianAbs(v);
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::cout << "usage: sensor_statistics LOG [--laser-label L]\n";
    return argc < 2 ? 2 : 0;
  }
  std::string label;
  for (int i = 2; i + 1 < argc; i += 2)
    if (std::string(argv[i]) == "--laser-label") label = argv[i + 1];
  try {
    auto src = io::openDataSource(argv[1]);
    alignment::AlignerOptions o;
    o.method = alignment::Method::PlIcp;
    std::vector<double> along, cross, heading_per_m, heading_per_rad, residual;
    size_t beams = 0, no_return = 0, pairs = 0, good = 0;
    std::vector<double> ranges;
    bool have_odom = false, have_key = false;
    common::Pose2 odom, key_odom;
    io::LaserScan key_scan;
    io::Measurement m;
    while (src->next(m)) {
      if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
        odom = od->pose;
        have_odom = true;
        continue;
      }
      const auto* scan = std::get_if<io::LaserScan>(&m);
      if (!scan || !have_odom || (!label.empty() && scan->label != label)) continue;
      beams += scan->size();
      no_return += scan->size() - scan->validCount();
      for (size_t i = 0; i < scan->size(); i += 7)
        if (scan->valid[i]) ranges.push_back(scan->ranges[i]);
      if (!have_key) {
        key_scan = *scan, key_odom = odom, have_key = true;
        continue;
      }
      const common::Pose2 inc = common::between(key_odom, odom);
      const double dist = std::hypot(inc.x, inc.y);
      if (dist < 1.0 && std::abs(inc.phi) < 15 * M_PI / 180) continue;
      ++pairs;
      const alignment::AlignmentResult r = alignment::align(key_scan, *scan, inc, o);
      if (r.converged && r.matchedFraction() > 0.8) {
        ++good;
        residual.push_back(r.rms_residual_m);
        // The odometry's error, in the frame of the earlier keyframe's heading of travel.
        const common::Pose2 e = common::between(r.transform, inc);
        const double dir = std::atan2(r.transform.y, r.transform.x);
        const double ea = std::cos(dir) * (inc.x - r.transform.x) + std::sin(dir) * (inc.y - r.transform.y);
        const double ec = -std::sin(dir) * (inc.x - r.transform.x) + std::cos(dir) * (inc.y - r.transform.y);
        const double travel = std::hypot(r.transform.x, r.transform.y), turn = std::abs(r.transform.phi);
        if (travel > 0.5) {
          along.push_back(ea / travel);
          cross.push_back(ec / travel);
          if (turn < 2 * M_PI / 180) heading_per_m.push_back(e.phi * 180 / M_PI / travel);
        }
        if (turn > 10 * M_PI / 180) heading_per_rad.push_back(e.phi / turn);
      }
      key_scan = *scan, key_odom = odom;
    }
    common::Json j = common::Json::object();
    j["log"] = std::string(argv[1]);
    j["keyframe_pairs"] = pairs;
    j["good_matches"] = good;
    j["odometry_along_track_per_m"] = summary(along);
    j["odometry_cross_track_per_m"] = summary(cross);
    j["odometry_heading_deg_per_m_straight"] = summary(heading_per_m);
    j["odometry_heading_per_rad_turned"] = summary(heading_per_rad);
    j["laser_residual_rms_m"] = summary(residual);
    j["laser_no_return_fraction"] = beams ? static_cast<double>(no_return) / static_cast<double>(beams) : 0.0;
    j["laser_median_range_m"] = common::percentile(ranges, 50);
    std::cout << j.dump() << "\n";
  } catch (const common::InputError& e) {
    std::cerr << "sensor_statistics: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
