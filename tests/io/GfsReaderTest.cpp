#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/GfsReader.h"

using namespace urbanslam;

namespace {

std::string writeText(const std::string& name, const std::string& text) {
  const auto p = test::scratchDir("gfs_" + name) / (name + ".gfs");
  std::ofstream(p) << text;
  return p.string();
}

std::string laserReading(int n, double x, double y, double theta, const std::string& ts) {
  std::ostringstream os;
  os << "LASER_READING " << n;
  for (int i = 0; i < n; ++i) os << " " << (i == 0 ? "81.91" : "3.5");
  os << " " << x << " " << y << " " << theta << " " << ts << "\n";
  return os.str();
}

struct Read {
  std::vector<io::OdometryReading> odometry;
  std::vector<io::LaserScan> scans;
  std::vector<io::OdometryReading> odometry_before_scan;  // latest odometry when each scan came
};

Read readAll(io::DataSource& src) {
  Read r;
  io::Measurement m;
  while (src.next(m)) {
    if (auto* o = std::get_if<io::OdometryReading>(&m)) r.odometry.push_back(*o);
    if (auto* s = std::get_if<io::LaserScan>(&m)) {
      r.scans.push_back(*s);
      r.odometry_before_scan.push_back(r.odometry.back());
    }
  }
  return r;
}

// Three readings as GMapping writes them: each ODOM line has its reading's time and the previous
// reading's pose (the first one its own); the odometry stalls before the scan at t=3, which
// carries the pose the stalled ODOM line misses.
const std::string kLog =
    "PARAM outfilename x.gfs\n"
    "PARAM maxrange 80\n"
    "ODOM 1.000 2.000 0.100000 1.000000\n"
    "ODOM 1.000 2.000 0.100000 2.000000\n"
    "ODOM 1.500 2.000 0.200000 3.000000\n" +
    laserReading(5, 1.8, 2.1, 0.9, "3.000000") +
    "SM_UPDATE 1 1.8 2.1 0.9 -10\n"
    "ODOM 1.800 2.100 0.900000 4.000000\n"
    "ODOM 2.000 2.200 1.000000 5.000000\n";

}  // namespace

TEST(GfsReader, DetectedAndOdometryPosesShiftedToTheirOwnTimes) {
  const std::string path = writeText("basic", kLog);
  EXPECT_EQ(io::detectLogFormat(path), io::LogFormat::Gfs);
  auto src = io::openDataSource(path);
  const Read r = readAll(*src);
  // Pose of line k+1 at the time of line k; the scan's pose at its own time; the last line's
  // time has no pose (no line follows it).
  ASSERT_EQ(r.odometry.size(), 4u);
  const double expect[4][4] = {{1, 1.0, 2.0, 0.1}, {2, 1.5, 2.0, 0.2}, {3, 1.8, 2.1, 0.9}, {4, 2.0, 2.2, 1.0}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(r.odometry[i].timestamp, expect[i][0]) << i;
    EXPECT_DOUBLE_EQ(r.odometry[i].pose.x, expect[i][1]) << i;
    EXPECT_DOUBLE_EQ(r.odometry[i].pose.y, expect[i][2]) << i;
    EXPECT_DOUBLE_EQ(r.odometry[i].pose.phi, expect[i][3]) << i;
  }
  ASSERT_EQ(r.scans.size(), 1u);
  const io::LaserScan& s = r.scans[0];
  EXPECT_DOUBLE_EQ(s.timestamp, 3.0);
  EXPECT_DOUBLE_EQ(r.odometry_before_scan[0].timestamp, 3.0);  // the scan's own pose came first
  EXPECT_DOUBLE_EQ(r.odometry_before_scan[0].pose.phi, 0.9);
  ASSERT_EQ(s.size(), 5u);
  EXPECT_EQ(s.valid[0], 0);  // 81.91 beyond maxrange 80: no return
  EXPECT_EQ(s.validCount(), 4u);
  EXPECT_NEAR(s.angle_min_rad, -M_PI / 2, 1e-12);
  EXPECT_NEAR(s.bearing(4), M_PI / 2, 1e-12);
}

TEST(GfsReader, BadInputIsAClearError) {
  const auto errorOf = [](const std::string& name, const std::string& text) {
    try {
      auto src = io::openDataSource(writeText(name, text));
      io::Measurement m;
      while (src->next(m)) {
      }
    } catch (const common::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string head = "PARAM outfilename x.gfs\nODOM 1 2 0.1 1.0\n";
  EXPECT_NE(errorOf("short_odom", head + "ODOM 1 2 0.1\n").find("short_odom.gfs:3: truncated ODOM"), std::string::npos);
  std::string cut = laserReading(5, 1, 2, 0, "2.0");
  cut = cut.substr(0, cut.rfind(' '));  // timestamp missing
  EXPECT_NE(errorOf("short_laser", head + cut + "\n").find("short_laser.gfs:3: truncated LASER_READING"), std::string::npos);
  EXPECT_NE(errorOf("nan_range", head + "LASER_READING 2 nan 3 1 2 0 2.0\n").find("nan_range.gfs:3"), std::string::npos);
  EXPECT_NE(errorOf("bad_count", head + "LASER_READING -4 1 2 0 2.0\n").find("invalid beam count"), std::string::npos);
}

// The benchmark's gfs log: the relation timestamps of mit-csail.relations are odometry times of
// the reader's stream, which is ordered, and the scans are the corrected log's 406.
TEST(GfsReader, MitCsailGfsFromSharedData) {
  const std::string gfs = test::sharedDataPath("freiburg_slam_benchmark/gfs/mit-csail.corrected.gfs.gz");
  const std::string rel = test::sharedDataPath("freiburg_slam_benchmark/relations/mit-csail.relations");
  if (gfs.empty() || rel.empty()) GTEST_SKIP() << "../shared/data (MIT CSAIL gfs log and relations) not present";
  auto src = io::openDataSource(gfs);
  const Read r = readAll(*src);
  EXPECT_EQ(r.scans.size(), 406u);
  for (size_t i = 1; i < r.odometry.size(); ++i) ASSERT_LT(r.odometry[i - 1].timestamp, r.odometry[i].timestamp) << i;
  std::set<long long> times;
  for (const auto& o : r.odometry) times.insert(std::llround(o.timestamp * 1000));
  std::ifstream in(rel);
  double t1, t2, x, y, z, roll, pitch, yaw;
  size_t n = 0, found = 0;
  while (in >> t1 >> t2 >> x >> y >> z >> roll >> pitch >> yaw) {
    n += 2;
    found += times.count(std::llround(t1 * 1000)) + times.count(std::llround(t2 * 1000));
  }
  EXPECT_EQ(n, 2 * 1172u);
  EXPECT_EQ(found, n);
}
