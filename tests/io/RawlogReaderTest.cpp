// MRPT's own rawlogs (package mrpt-common) as independent references.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/RawlogReader.h"

using namespace urbanslam;

namespace {
const std::string kSena = "/usr/share/mrpt/datasets/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog";
}

// The classic act/SF rawlog starts with a frame that has no action before it; MRPT's pair
// iterator drops it (224 scans), RawLogViewer shows 225. Odometry path: 76.35 m (RawLogViewer).
TEST(RawlogReader, SensoryFrameRawlogKeepsTheLeadingFrame) {
  if (!std::filesystem::exists(kSena)) GTEST_SKIP() << kSena << " not installed (package mrpt-common)";
  io::RawlogReader reader(kSena);
  io::Measurement m;
  size_t scans = 0, odo = 0;
  double path = 0;
  common::Pose2 last;
  bool have = false;
  while (reader.next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) {
      ++scans;
      EXPECT_EQ(s->size(), 361u);
      EXPECT_NEAR(s->sensor_pose.x, 0.78, 1e-6);
    }
    if (auto* o = std::get_if<io::OdometryReading>(&m)) {
      ++odo;
      if (have)
        path += std::hypot(o->pose.x - last.x, o->pose.y - last.y);
      else
        path += std::hypot(o->pose.x, o->pose.y);  // first increment from the origin
      last = o->pose;
      have = true;
    }
  }
  EXPECT_EQ(scans, 225u);
  EXPECT_EQ(odo, 224u);
  EXPECT_NEAR(path, 76.35, 0.01);
  EXPECT_EQ(reader.format(), "MRPT rawlog (actions/sensory frames)");
}

TEST(RawlogReader, CorruptAndTruncatedFilesAreClearErrors) {
  const auto d = test::scratchDir("rawlog_bad");
  const std::string src = test::repoPath("rawlogs/intel.rawlog");
  // Truncated: the first 40% of the gzip stream.
  {
    std::ifstream in(src, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(d / "trunc.rawlog", std::ios::binary) << bytes.substr(0, bytes.size() * 4 / 10);
  }
  try {
    auto r = io::openDataSource((d / "trunc.rawlog").string());
    io::Measurement m;
    while (r->next(m)) {
    }
    FAIL() << "no error on a truncated rawlog";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trunc"), std::string::npos) << e.what();
  }
  // Binary garbage is not a rawlog.
  {
    std::ofstream f(d / "garbage.rawlog", std::ios::binary);
    for (int i = 0; i < 4096; ++i) f.put(static_cast<char>((i * 7919) % 256));
  }
  EXPECT_THROW(
      {
        auto r = io::openDataSource((d / "garbage.rawlog").string());
        io::Measurement m;
        while (r->next(m)) {
        }
      },
      common::InputError);
  std::ofstream(d / "text.txt") << "hello, I am not a log\n";
  EXPECT_THROW(io::openDataSource((d / "text.txt").string()), common::InputError);
  std::ofstream(d / "empty.rawlog") << "";
  EXPECT_THROW(io::openDataSource((d / "empty.rawlog").string()), common::InputError);
  EXPECT_THROW(io::openDataSource((d / "missing.rawlog").string()), common::InputError);
}

// Camera images: embedded in the rawlog, stored externally beside it in "<name>_Images/", and
// the left image of a stereo pair.
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/serialization/CArchive.h>

TEST(RawlogReader, ImagesEmbeddedExternalAndStereo) {
  const auto d = test::scratchDir("rawlog_images");
  std::filesystem::create_directories(d / "cam_Images");
  mrpt::img::CImage img(64, 48, mrpt::img::CH_GRAY);
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 64; ++c) *img.ptr<uint8_t>(c, r) = static_cast<uint8_t>(r * 4 + c);
  img.saveToFile((d / "cam_Images" / "frame0.png").string());
  {
    mrpt::io::CFileGZOutputStream f((d / "cam.rawlog").string());
    auto arch = mrpt::serialization::archiveFrom(f);
    mrpt::obs::CObservationImage embedded;
    embedded.sensorLabel = "CAMERA";
    embedded.timestamp = mrpt::Clock::fromDouble(10.0);
    embedded.image = img;
    arch << embedded;
    mrpt::obs::CObservationImage external;
    external.sensorLabel = "CAMERA";
    external.timestamp = mrpt::Clock::fromDouble(11.0);
    external.image.setExternalStorage("frame0.png");
    arch << external;
    mrpt::obs::CObservationStereoImages stereo;
    stereo.sensorLabel = "STEREO";
    stereo.timestamp = mrpt::Clock::fromDouble(12.0);
    stereo.imageLeft = img;
    stereo.imageRight = mrpt::img::CImage(64, 48, mrpt::img::CH_GRAY);
    arch << stereo;
  }
  io::RawlogReader reader((d / "cam.rawlog").string());
  io::Measurement m;
  std::vector<io::CameraImage> images;
  while (reader.next(m))
    if (auto* c = std::get_if<io::CameraImage>(&m)) images.push_back(*c);
  ASSERT_EQ(images.size(), 3u);
  for (const auto& c : images) {
    ASSERT_EQ(c.width, 64);
    ASSERT_EQ(c.height, 48);
    EXPECT_EQ((*c.pixels)[5 * 64 + 7], 5 * 4 + 7);
  }
  EXPECT_EQ(images[1].source.find("frame0.png") != std::string::npos, true) << images[1].source;
  EXPECT_EQ(images[2].label, "STEREO");
  EXPECT_DOUBLE_EQ(images[1].timestamp, 11.0);
}

// MRPT segfaults while it reads a robot movement whose estimation method is not odometry and
// whose pose change is not a pose PDF; the reader refuses those fields as MRPT reads them.
TEST(RawlogReader, RobotMovementWithoutAPosePdfIsAClearError) {
  const std::string path = test::repoPath("fuzz/regressions/rawlog/movement-estimation-method-not-odometry.rawlog");
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const size_t method = bytes.find("CActionRobotMovement2D") + 22 + 1;  // after the name and the version byte
  const auto readAll = [](const std::string& p) {
    io::RawlogReader reader(p);
    io::Measurement m;
    while (reader.next(m)) {
    }
  };
  const auto expectError = [&](const std::string& p, const std::string& fragment) {
    try {
      readAll(p);
      ADD_FAILURE() << p << " read without error";
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(p + ": entry ", 0), 0u) << e.what();
    }
  };
  expectError(path, "unknown estimation method 6815744");
  // Method 1 (scan matching) followed by a CPose2D instead of a pose PDF.
  const auto d = test::scratchDir("rawlog_movement");
  bytes.replace(method, 4, std::string("\x01\x00\x00\x00", 4));
  const std::string pose2d = (d / "pose2d.rawlog").string();
  std::ofstream(pose2d, std::ios::binary) << bytes;
  expectError(pose2d, "its pose change is a CPose2D, not a pose PDF");
}

// MRPT stores a flag's byte as it is in the file; a byte other than 0 or 1 is a corrupt entry (a
// bool holding it is undefined behaviour).
TEST(RawlogReader, AFlagByteOtherThanZeroOrOneIsACorruptEntry) {
  const std::string path = test::repoPath("fuzz/regressions/rawlog/scan-right-to-left-byte-254.rawlog");
  try {
    io::RawlogReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
    ADD_FAILURE() << path << " read without error";
  } catch (const common::InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": entry 1: corrupt entry: laser scan rightToLeft flag byte is 254");
  }
}
