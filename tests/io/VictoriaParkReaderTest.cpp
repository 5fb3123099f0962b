#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/VictoriaParkReader.h"

using namespace urbanslam;

TEST(VictoriaParkReader, MergesTheThreeFilesInTimeOrder) {
  io::VictoriaParkReader reader(test::repoPath("rawlogs/victoria-park-excerpt"));
  io::Measurement m;
  double last_t = -1;
  size_t scans = 0, drive = 0, gps = 0;
  io::LaserScan first;
  while (reader.next(m)) {
    const double t = io::timestampOf(m);
    EXPECT_GE(t, last_t);
    last_t = t;
    if (auto* s = std::get_if<io::LaserScan>(&m)) {
      if (scans++ == 0) first = *s;
    }
    drive += std::holds_alternative<io::DriveReading>(m);
    gps += std::holds_alternative<io::GpsFix>(m);
  }
  EXPECT_EQ(scans, 250u);
  EXPECT_EQ(drive, 2123u);
  EXPECT_EQ(gps, 90u);
  // First record of LASER.txt: time 0.852 s, then 0.83, 0.84, ... metres; 81.91 = no return.
  ASSERT_EQ(first.size(), 361u);
  EXPECT_DOUBLE_EQ(first.timestamp, 0.852);
  EXPECT_FLOAT_EQ(first.ranges[0], 0.83f);
  EXPECT_TRUE(first.valid[0]);
  EXPECT_FALSE(first.valid[13]);  // 81.91
  EXPECT_NEAR(first.bearing(0), -M_PI / 2, 1e-12);
  EXPECT_NEAR(first.bearing(360), M_PI / 2, 1e-12);
}

TEST(VictoriaParkReader, TruncatedLaserRecordIsAnError) {
  const auto d = test::scratchDir("vp_trunc");
  std::ofstream(d / "LASER.txt") << "1.0\t2.0\t3.0";
  std::ofstream(d / "DRS.txt") << "0.5 1.0 0.0\n";
  std::ofstream(d / "GPS.txt") << "";
  try {
    io::VictoriaParkReader reader(d.string());
    FAIL() << "no error";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated (2 of 361 ranges)"), std::string::npos) << e.what();
  }
}

TEST(VictoriaParkReader, ReadsTheOriginalZipFromSharedData) {
  const std::string zip = test::sharedDataPath("victoria_park/victoria_park_ascii.zip");
  if (zip.empty()) GTEST_SKIP() << "../shared/data/victoria_park not present";
  io::VictoriaParkReader reader(zip);
  io::Measurement m;
  size_t scans = 0, drive = 0, gps = 0;
  while (reader.next(m)) {
    scans += std::holds_alternative<io::LaserScan>(m);
    drive += std::holds_alternative<io::DriveReading>(m);
    gps += std::holds_alternative<io::GpsFix>(m);
  }
  EXPECT_EQ(scans, 7230u);
  EXPECT_EQ(drive, 61763u);
  EXPECT_EQ(gps, 948u);
}
