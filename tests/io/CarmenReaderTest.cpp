#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <zlib.h>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/CarmenReader.h"
#include "urbanslam/io/DataSource.h"

using namespace urbanslam;
using common::Pose2;

namespace {

const std::string kExcerpt = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");

std::vector<std::string> gzLines(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  std::vector<std::string> lines;
  char buf[1 << 16];
  while (gzgets(f, buf, sizeof buf)) {
    std::string s(buf);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    lines.push_back(s);
  }
  gzclose(f);
  return lines;
}

std::vector<std::string> split(const std::string& s) {
  std::istringstream is(s);
  std::vector<std::string> f;
  std::string t;
  while (is >> t) f.push_back(t);
  return f;
}

struct ReadBack {
  std::vector<io::LaserScan> scans;
  std::vector<io::OdometryReading> odometry;
  std::vector<io::ReferencePose> reference;
  std::vector<Pose2> raw_at_scan;  // latest odometry when each scan arrived
};

ReadBack readAll(io::DataSource& src) {
  ReadBack r;
  io::Measurement m;
  while (src.next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) {
      r.scans.push_back(*s);
      r.raw_at_scan.push_back(r.odometry.empty() ? Pose2{} : r.odometry.back().pose);
    } else if (auto* o = std::get_if<io::OdometryReading>(&m)) {
      r.odometry.push_back(*o);
    } else if (auto* p = std::get_if<io::ReferencePose>(&m)) {
      r.reference.push_back(*p);
    }
  }
  return r;
}

std::string writeText(const std::string& name, const std::string& text) {
  const auto p = test::scratchDir("carmen_" + name) / (name + ".log");
  std::ofstream(p) << text;
  return p.string();
}

std::string flaser(int n, const std::string& range_value, double ts) {
  std::ostringstream os;
  os << "FLASER " << n;
  for (int i = 0; i < n; ++i) os << " " << (i == n / 2 ? range_value : "2.5");
  os << " 0 0 0 0 0 0 " << ts << " host " << ts << "\n";
  return os.str();
}

}  // namespace

TEST(CarmenReader, CorrectedLogGivesScansReferenceAndTimestamps) {
  io::CarmenReader reader(kExcerpt);
  EXPECT_TRUE(reader.info().corrected);
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.scans.size(), 80u);
  ASSERT_EQ(r.reference.size(), 80u);
  // First FLASER of the Intel corrected log: 180 beams over 180° at 1°, timestamp 32.9068.
  EXPECT_EQ(r.scans[0].ranges.size(), 180u);
  EXPECT_NEAR(r.scans[0].timestamp, 32.9068, 1e-9);
  EXPECT_NEAR(r.scans[0].angle_increment_rad, M_PI / 180, 1e-12);
  EXPECT_NEAR(r.scans[0].sensor_pose.phi + r.scans[0].bearing(0), -M_PI / 2, 1e-12);  // first beam to the right
  EXPECT_NEAR(r.scans[0].sensor_pose.phi + r.scans[0].bearing(179), 89 * M_PI / 180, 1e-12);
  EXPECT_NEAR(r.reference[0].pose.x, 0.600266, 1e-9);
  EXPECT_NEAR(r.reference[0].pose.phi, -0.354665, 1e-9);
  // 81.83 m no-returns are invalid, real returns valid.
  EXPECT_GT(r.scans[0].validCount(), 100u);
  for (size_t i = 0; i < r.scans[0].size(); ++i)
    if (r.scans[0].ranges[i] > 80) {
      EXPECT_FALSE(r.scans[0].valid[i]);
    }
}

// The raw odometry between two scans must equal the log's own increments inside the segment:
// from the anchor ODOM (the corrected pose of scan k) to the last ODOM before scan k+1.
TEST(CarmenReader, RawOdometryMatchesSegmentIncrements) {
  io::CarmenReader reader(kExcerpt);
  const ReadBack r = readAll(reader);
  // Independent parse of the text: anchor and last ODOM per segment.
  std::vector<Pose2> anchors, ends;
  bool after_flaser = false;
  Pose2 last{};
  for (const auto& line : gzLines(kExcerpt)) {
    const auto f = split(line);
    if (f.empty()) continue;
    if (f[0] == "FLASER") {
      ends.push_back(last);
      after_flaser = true;
      continue;
    }
    if (f[0] == "ODOM") {
      const Pose2 p{std::stod(f[1]), std::stod(f[2]), std::stod(f[3])};
      if (after_flaser) anchors.push_back(p);
      last = p;
    }
    after_flaser = false;
  }
  ASSERT_EQ(ends.size(), r.scans.size());
  size_t checked = 0;
  double largest_gap = 0;
  for (size_t k = 0; k + 1 < r.scans.size(); ++k) {
    const Pose2 expected = common::between(anchors[k], ends[k + 1]);
    const Pose2 got = common::between(r.raw_at_scan[k], r.raw_at_scan[k + 1]);
    EXPECT_NEAR(got.x, expected.x, 1e-9) << "scan " << k;
    EXPECT_NEAR(got.y, expected.y, 1e-9) << "scan " << k;
    EXPECT_NEAR(common::wrapToPi(got.phi - expected.phi), 0, 1e-9) << "scan " << k;
    // Raw odometry must differ from the corrected poses (it is not fed the corrections).
    const Pose2 corr = common::between(r.reference[k].pose, r.reference[k + 1].pose);
    largest_gap = std::max(largest_gap, std::abs(common::wrapToPi(corr.phi - got.phi)));
    ++checked;
  }
  EXPECT_EQ(checked, 79u);
  EXPECT_GT(largest_gap, 1e-3);
}

TEST(CarmenReader, BadInputIsAClearError) {
  const auto expectError = [](const std::string& path, const std::string& fragment) {
    try {
      io::CarmenReader reader(path);
      io::Measurement m;
      while (reader.next(m)) {
      }
      ADD_FAILURE() << "no error for " << path;
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expectError(writeText("nan", flaser(5, "nan", 1.0)), "NaN");
  expectError(writeText("neg", flaser(5, "-1.0", 1.0)), "negative range");
  expectError(writeText("trunc", "FLASER 5 1 2 3\n"), ":1: truncated laser line");
  expectError(writeText("count", "FLASER x 1 2\n"), "beam count");
  expectError(writeText("odom", "ODOM 1 2\n"), "truncated ODOM line");
  EXPECT_THROW(io::CarmenReader("/nonexistent.log"), common::InputError);
}

TEST(CarmenReader, LogWithoutOdomLinesUsesTheLaserOdometryFields) {
  const std::string text = "# raw log\n" + flaser(3, "1.0", 10.0) + flaser(3, "1.0", 11.0);
  io::CarmenReader reader(writeText("noodom", text));
  EXPECT_FALSE(reader.info().corrected);
  const ReadBack r = readAll(reader);
  EXPECT_EQ(r.scans.size(), 2u);
  EXPECT_EQ(r.odometry.size(), 2u);
  EXPECT_TRUE(r.reference.empty());
  EXPECT_EQ(r.scans[1].timestamp, 11.0);
}

TEST(CarmenReader, FreiburgCorrectedLogsFromSharedData) {
  const std::string fr079 = test::sharedDataPath("freiburg_slam_benchmark/corrected_logs/freiburg-079-corrected.log.gz");
  if (fr079.empty()) GTEST_SKIP() << "../shared/data (Freiburg corrected logs) not present";
  io::CarmenReader reader(fr079);
  const ReadBack r = readAll(reader);
  EXPECT_TRUE(reader.info().corrected);
  EXPECT_EQ(r.scans.size(), 4791u);
  EXPECT_EQ(r.reference.size(), 4791u);
  EXPECT_EQ(r.scans[0].ranges.size(), 360u);
  EXPECT_NEAR(r.scans[0].angle_increment_rad, 0.5 * M_PI / 180, 1e-12);
}

// Front and rear lasers are told apart by label; the rear one looks backwards.
TEST(CarmenReader, FrontAndRearLasersByLabel) {
  std::string rear = flaser(4, "1.0", 5.0);
  rear.replace(0, 6, "RLASER");
  const std::string text = "PARAM robot_rearlaser_offset -0.3 h 0\n" + flaser(4, "1.0", 5.0) + rear;
  io::CarmenReader reader(writeText("rear", text));
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.scans.size(), 2u);
  EXPECT_EQ(r.scans[0].label, "FLASER");
  EXPECT_EQ(r.scans[1].label, "RLASER");
  EXPECT_NEAR(r.scans[1].sensor_pose.x, -0.3, 1e-12);
  // The rear laser looks backwards: its first (rightmost) beam points to the vehicle's left,
  // its last to the vehicle's right.
  const auto& s = r.scans[1];
  EXPECT_NEAR(common::wrapToPi(s.sensor_pose.phi + s.bearing(0) - M_PI / 2), 0, 1e-12);
  EXPECT_NEAR(common::wrapToPi(s.sensor_pose.phi + s.bearing(3) + M_PI / 2), 0, 1e-12);
  const auto& f = r.scans[0];
  EXPECT_NEAR(common::wrapToPi(f.sensor_pose.phi + f.bearing(0) + M_PI / 2), 0, 1e-12);
}

// Timestamps printed with too few digits (MIT CSAIL: "1.13486e+09") repeat; the scan index
// orders the log instead.
TEST(CarmenReader, RepeatedTimestampsFallBackToTheScanIndex) {
  std::string text;
  for (int i = 0; i < 10; ++i)
    text += "ODOM " + std::to_string(0.1 * i) + " 0 0 0 0 0 1.13486e+09 h 1.13486e+09\n" + flaser(3, "1.0", 1.13486e+09);
  io::CarmenReader reader(writeText("repeated", text));
  EXPECT_FALSE(reader.info().has_timestamps);
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.scans.size(), 10u);
  for (size_t i = 0; i < r.scans.size(); ++i) EXPECT_DOUBLE_EQ(r.scans[i].timestamp, static_cast<double>(i + 1));
  EXPECT_NE(reader.format().find("scan index"), std::string::npos);
}

// The Freiburg corrected logs print 6 significant digits, so after 1000 s the Intel log's odometry
// bursts share one printed time. The reader spreads such lines, in file order, over the 10 ms
// the printed value stands for; a scan keeps the time of the reading it was logged with.
TEST(CarmenReader, ReadingsSharingAPrintedTimeAreSpreadOverItsStep) {
  const auto odom = [](double x, const std::string& t) { return "ODOM " + std::to_string(x) + " 0 0 0 0 0 " + t + " h " + t + "\n"; };
  std::string rear = flaser(3, "1.0", 2670.16);
  rear.replace(0, 6, "RLASER");
  const std::string text = odom(0.0, "2670.15") + odom(0.1, "2670.16") + odom(0.2, "2670.16") + flaser(3, "1.0", 2670.16) + rear +
                           odom(0.3, "2670.16") + odom(0.4, "2670.17") + odom(0.5, "2670.2") + odom(0.6, "2670.2");
  io::CarmenReader reader(writeText("burst", text));
  ASSERT_TRUE(reader.info().has_timestamps);
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.odometry.size(), 7u);
  ASSERT_EQ(r.scans.size(), 2u);
  EXPECT_DOUBLE_EQ(r.odometry[0].timestamp, 2670.15);  // alone at its printed time: unchanged
  EXPECT_DOUBLE_EQ(r.odometry[4].timestamp, 2670.17);
  // Three instants at "2670.16": the middle of each third of [2670.155, 2670.165).
  EXPECT_NEAR(r.odometry[1].timestamp, 2670.155 + 0.01 / 6, 1e-9);
  EXPECT_NEAR(r.odometry[2].timestamp, 2670.16, 1e-9);
  EXPECT_NEAR(r.odometry[3].timestamp, 2670.165 - 0.01 / 6, 1e-9);
  // The front and rear scans stay at the instant of the odometry line before them.
  EXPECT_EQ(r.scans[0].timestamp, r.odometry[2].timestamp);
  EXPECT_EQ(r.scans[1].timestamp, r.odometry[2].timestamp);
  EXPECT_NEAR(r.raw_at_scan[0].x, 0.2, 1e-9);  // and the order of the file is kept
  // %g drops trailing zeros: "2670.2" is 2670.20 to the log's 6 digits, so a 10 ms step too.
  EXPECT_NEAR(r.odometry[5].timestamp, 2670.1975, 1e-9);
  EXPECT_NEAR(r.odometry[6].timestamp, 2670.2025, 1e-9);
}

// A fixed-point log ("%.2f": trailing zeros kept) has one step for every time, however many
// digits the number has: "5.25" stands for [5.245, 5.255), not for 5.25 to 6 digits.
TEST(CarmenReader, FixedPointTimesKeepTheirOwnStep) {
  const auto odom = [](double x, const std::string& t) { return "ODOM " + std::to_string(x) + " 0 0 0 0 0 " + t + " h " + t + "\n"; };
  const std::string text = odom(0.0, "5.20") + odom(0.1, "5.25") + odom(0.2, "5.25") + odom(0.3, "2670.16") + flaser(3, "1.0", 2670.16);
  io::CarmenReader reader(writeText("fixed", text));
  ASSERT_TRUE(reader.info().has_timestamps);
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.odometry.size(), 4u);
  EXPECT_NEAR(r.odometry[1].timestamp, 5.2475, 1e-9);
  EXPECT_NEAR(r.odometry[2].timestamp, 5.2525, 1e-9);
}

// ROBOTLASER1 as CARMEN's logger writes it: after the remissions, the laser and robot poses and
// tv rv forward_safety_dist side_safety_dist turn_axis, then timestamp, hostname, logger time.
TEST(CarmenReader, RobotLaserCarriesItsGeometryAndMount) {
  const std::string line =
      "ROBOTLASER1 0 -2.0 4.0 0.5 30.0 0.01 0 9 1 2 3 4 30 6 7 8 9 0 "
      "1.2 2.1 0.8 1.0 2.0 0.3 0 0 0 0 0 12.345678 host 12.345678\n";
  io::CarmenReader reader(writeText("robotlaser", line));
  const ReadBack r = readAll(reader);
  ASSERT_EQ(r.scans.size(), 1u);
  const auto& s = r.scans[0];
  EXPECT_EQ(s.label, "ROBOTLASER1");
  EXPECT_DOUBLE_EQ(s.timestamp, 12.345678);
  EXPECT_EQ(s.size(), 9u);
  EXPECT_EQ(s.validCount(), 8u);  // the 30 m reading is the sensor's maximum: no return
  EXPECT_NEAR(s.angle_increment_rad, 0.5, 1e-12);
  // Beam 0 points at start_angle in the laser frame; the laser sits at robot^-1 * laser pose.
  const Pose2 mount = common::between(Pose2{1.0, 2.0, 0.3}, Pose2{1.2, 2.1, 0.8});
  EXPECT_NEAR(s.sensor_pose.x, mount.x, 1e-12);
  EXPECT_NEAR(s.sensor_pose.y, mount.y, 1e-12);
  EXPECT_NEAR(common::wrapToPi(s.sensor_pose.phi + s.bearing(0) - (0.5 - 2.0)), 0, 1e-12);
  ASSERT_EQ(r.odometry.size(), 1u);  // no ODOM lines: the robot pose is the odometry
  EXPECT_NEAR(r.odometry[0].pose.phi, 0.3, 1e-12);
  try {
    io::CarmenReader short_reader(writeText("robotlaser_short", line.substr(0, line.find(" host"))));
    readAll(short_reader);
    ADD_FAILURE() << "a ROBOTLASER1 line without hostname and logger time was read";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated ROBOTLASER1"), std::string::npos) << e.what();
  }
}
