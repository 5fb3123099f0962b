// convert → read back: the same observations and timestamps, in both rawlog layouts.
#include <gtest/gtest.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "TestPaths.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/RawlogReader.h"
#include "urbanslam/io/RawlogWriter.h"

using namespace urbanslam;

namespace {

std::vector<io::Measurement> readAll(const std::string& path) {
  auto src = io::openDataSource(path);
  std::vector<io::Measurement> all;
  io::Measurement m;
  while (src->next(m)) all.push_back(m);
  return all;
}

template <typename T>
std::vector<T> only(const std::vector<io::Measurement>& all) {
  std::vector<T> out;
  for (const auto& m : all)
    if (auto* p = std::get_if<T>(&m)) out.push_back(*p);
  return out;
}

void convert(const std::string& in, const std::string& out, io::RawlogLayout layout) {
  auto src = io::openDataSource(in);
  io::RawlogWriter w(out, layout);
  io::Measurement m;
  while (src->next(m)) w.write(m);
  w.close();
}

// Two scans are the same observation when every beam's range, validity and world bearing agree.
void expectSameScan(const io::LaserScan& a, const io::LaserScan& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_NEAR(a.timestamp, b.timestamp, 1e-6);
  EXPECT_EQ(a.label, b.label);
  EXPECT_NEAR(a.max_range_m, b.max_range_m, 1e-5);
  EXPECT_NEAR(a.sensor_pose.x, b.sensor_pose.x, 1e-6);
  EXPECT_NEAR(a.sensor_pose.y, b.sensor_pose.y, 1e-6);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.ranges[i], b.ranges[i]);
    EXPECT_EQ(a.valid[i], b.valid[i]);
    EXPECT_NEAR(common::wrapToPi(a.sensor_pose.phi + a.bearing(i) - b.sensor_pose.phi - b.bearing(i)), 0, 1e-6);
  }
}

}  // namespace

TEST(RoundTrip, CarmenToObservationRawlogKeepsEverything) {
  const std::string in = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const std::string out = (test::scratchDir("rt_obs") / "x.rawlog").string();
  convert(in, out, io::RawlogLayout::Observations);
  const auto a = readAll(in), b = readAll(out);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].index(), b[i].index()) << "measurement " << i;
    EXPECT_NEAR(io::timestampOf(a[i]), io::timestampOf(b[i]), 1e-6);
  }
  const auto sa = only<io::LaserScan>(a), sb = only<io::LaserScan>(b);
  ASSERT_EQ(sa.size(), 80u);
  for (size_t i = 0; i < sa.size(); ++i) expectSameScan(sa[i], sb[i]);
  const auto oa = only<io::OdometryReading>(a), ob = only<io::OdometryReading>(b);
  for (size_t i = 0; i < oa.size(); ++i) {
    EXPECT_NEAR(oa[i].pose.x, ob[i].pose.x, 1e-9);
    EXPECT_NEAR(oa[i].pose.y, ob[i].pose.y, 1e-9);
    EXPECT_NEAR(common::wrapToPi(oa[i].pose.phi - ob[i].pose.phi), 0, 1e-9);
  }
  const auto ra = only<io::ReferencePose>(a), rb = only<io::ReferencePose>(b);
  ASSERT_EQ(ra.size(), rb.size());
  for (size_t i = 0; i < ra.size(); ++i) EXPECT_NEAR(ra[i].pose.x, rb[i].pose.x, 1e-9);
}

TEST(RoundTrip, FramesLayoutKeepsScansAndOdometryIncrements) {
  const std::string in = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const std::string out = (test::scratchDir("rt_sf") / "x.rawlog").string();
  convert(in, out, io::RawlogLayout::SensoryFrames);
  io::RawlogReader reader(out);
  EXPECT_EQ(reader.format(), "MRPT rawlog (observations)");  // format known only after reading
  std::vector<io::Measurement> b;
  io::Measurement m;
  while (reader.next(m)) b.push_back(m);
  EXPECT_EQ(reader.format(), "MRPT rawlog (actions/sensory frames)");
  const auto a = readAll(in);
  const auto sa = only<io::LaserScan>(a), sb = only<io::LaserScan>(b);
  ASSERT_EQ(sa.size(), sb.size());
  for (size_t i = 0; i < sa.size(); ++i) expectSameScan(sa[i], sb[i]);
  // Actions carry increments: the chained odometry differs from the original by one rigid
  // transform (the first reading's pose), so compare consecutive increments.
  const auto oa = only<io::OdometryReading>(a), ob = only<io::OdometryReading>(b);
  ASSERT_EQ(ob.size() + 1, oa.size());  // the first reading only sets the origin of the increments
  for (size_t i = 1; i + 1 < oa.size(); ++i) {
    const auto da = common::between(oa[i].pose, oa[i + 1].pose);
    const auto db = common::between(ob[i - 1].pose, ob[i].pose);
    EXPECT_NEAR(da.x, db.x, 1e-6);
    EXPECT_NEAR(da.y, db.y, 1e-6);
    EXPECT_NEAR(common::wrapToPi(da.phi - db.phi), 0, 1e-6);
    EXPECT_NEAR(oa[i + 1].timestamp, ob[i].timestamp, 1e-6);
  }
}

// A log without odometry (speed + steering) in the classic layout: MRPT's own pair reader (what
// icp-slam and rbpf-slam use) must see one action/frame pair per scan, not one frame holding all.
TEST(RoundTrip, FramesLayoutWithoutOdometryGivesMrptOnePairPerScan) {
  const std::string in = test::repoPath("rawlogs/victoria-park-excerpt");
  const std::string out = (test::scratchDir("rt_sf_vp") / "vp.rawlog").string();
  convert(in, out, io::RawlogLayout::SensoryFrames);
  const size_t scans = only<io::LaserScan>(readAll(in)).size();
  ASSERT_EQ(scans, 250u);
  mrpt::io::CFileGZInputStream f(out);
  auto arch = mrpt::serialization::archiveFrom(f);
  mrpt::obs::CActionCollection::Ptr acts;
  mrpt::obs::CSensoryFrame::Ptr sf;
  mrpt::obs::CObservation::Ptr obs;
  size_t pos = 0, pairs = 0, scans_read = 0;
  while (mrpt::obs::CRawlog::getActionObservationPairOrObservation(arch, acts, sf, obs, pos)) {
    ASSERT_TRUE(sf) << "entry " << pos << " is not an action/frame pair";
    size_t in_frame = 0;
    for (const auto& o : *sf) in_frame += o->GetRuntimeClass() == CLASS_ID(mrpt::obs::CObservation2DRangeScan);
    EXPECT_LE(in_frame, 1u) << "frame " << pairs;
    scans_read += in_frame;
    ++pairs;
  }
  EXPECT_EQ(scans_read, scans);
  EXPECT_GE(pairs, scans);
}

TEST(RoundTrip, VictoriaParkDriveAndGpsSurvive) {
  const std::string in = test::repoPath("rawlogs/victoria-park-excerpt");
  const std::string out = (test::scratchDir("rt_vp") / "vp.rawlog").string();
  convert(in, out, io::RawlogLayout::Observations);
  const auto a = readAll(in), b = readAll(out);
  ASSERT_EQ(a.size(), b.size());
  const auto da = only<io::DriveReading>(a), db = only<io::DriveReading>(b);
  ASSERT_EQ(da.size(), 2123u);
  for (size_t i = 0; i < da.size(); ++i) {
    EXPECT_EQ(da[i].speed_mps, db[i].speed_mps);
    EXPECT_EQ(da[i].steering_rad, db[i].steering_rad);
  }
  const auto ga = only<io::GpsFix>(a), gb = only<io::GpsFix>(b);
  ASSERT_EQ(ga.size(), 90u);
  for (size_t i = 0; i < ga.size(); ++i) EXPECT_NEAR(ga[i].x_m, gb[i].x_m, 1e-9);
  const auto sa = only<io::LaserScan>(a), sb = only<io::LaserScan>(b);
  ASSERT_EQ(sa.size(), 250u);
  for (size_t i = 0; i < sa.size(); ++i) expectSameScan(sa[i], sb[i]);
}

// Images stored beside the rawlog: nothing of an unfinished writer is left behind, and a
// finished one replaces the images folder of an earlier rawlog of the same name whole.
TEST(RoundTrip, ExternalImagesFolderIsReplacedWholeAtClose) {
  namespace fs = std::filesystem;
  const fs::path dir = test::scratchDir("rt_images");
  const std::string out = (dir / "cam.rawlog").string();
  const auto image = [](double t, uint8_t v) {
    io::CameraImage im;
    im.timestamp = t;
    im.label = "CAMERA";
    im.width = 8, im.height = 6;
    im.pixels = std::make_shared<const std::vector<uint8_t>>(48, v);
    return io::Measurement(im);
  };
  {
    io::RawlogWriter w(out, io::RawlogLayout::Observations, 5, io::ImageStorage::External);
    w.write(image(1.0, 10));
    // not closed: as if the run was interrupted
  }
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
  fs::create_directories(dir / "cam_Images");
  std::ofstream(dir / "cam_Images" / "CAMERA_000007.png") << "an earlier run's image";
  {
    io::RawlogWriter w(out, io::RawlogLayout::Observations, 5, io::ImageStorage::External);
    w.write(image(1.0, 10));
    w.write(image(2.0, 200));
    w.close();
  }
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir / "cam_Images")) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"CAMERA_000000.png", "CAMERA_000001.png"}));
  // Read back: the pixels come from the files beside the rawlog.
  auto src = io::openDataSource(out);
  io::Measurement m;
  std::vector<uint8_t> firsts;
  while (src->next(m))
    if (const auto* im = std::get_if<io::CameraImage>(&m)) firsts.push_back(im->pixels->at(0));
  EXPECT_EQ(firsts, (std::vector<uint8_t>{10, 200}));
}

// A camera's calibration goes into the rawlog as MRPT keeps it (cameraParams, and cameraPose in
// MRPT's camera frame: +Z the optical axis) and comes back as it was; an image without one comes
// back without.
TEST(RoundTrip, CameraCalibrationSurvivesInMrptsConvention) {
  const std::string out = (test::scratchDir("rt_calibration") / "cam.rawlog").string();
  const auto image = [](double t, std::optional<io::CameraCalibration> c) {
    io::CameraImage im;
    im.timestamp = t;
    im.label = "CAMERA";
    im.width = 64, im.height = 48;
    im.pixels = std::make_shared<const std::vector<uint8_t>>(64 * 48, 100);
    im.calibration = c;
    return io::Measurement(im);
  };
  io::CameraCalibration side;
  side.fx_px = 32, side.fy_px = 33, side.cx_px = 31.5, side.cy_px = 35.5;
  side.mount = {1.0, -0.25, M_PI / 2};  // looking left
  io::CameraCalibration back = side;
  back.mount.phi = -2.5;
  {
    io::RawlogWriter w(out, io::RawlogLayout::Observations, 5, io::ImageStorage::Embedded);
    w.write(image(1.0, side));
    w.write(image(2.0, back));
    w.write(image(3.0, std::nullopt));
    w.close();
  }
  std::vector<std::optional<io::CameraCalibration>> got;
  for (const auto& m : readAll(out))
    if (const auto* im = std::get_if<io::CameraImage>(&m)) got.push_back(im->calibration);
  ASSERT_EQ(got.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const io::CameraCalibration& want = k == 0 ? side : back;
    ASSERT_TRUE(got[k].has_value()) << k;
    EXPECT_DOUBLE_EQ(got[k]->fx_px, want.fx_px);
    EXPECT_DOUBLE_EQ(got[k]->fy_px, want.fy_px);
    EXPECT_DOUBLE_EQ(got[k]->cx_px, want.cx_px);
    EXPECT_DOUBLE_EQ(got[k]->cy_px, want.cy_px);
    EXPECT_NEAR(got[k]->mount.x, want.mount.x, 1e-12);
    EXPECT_NEAR(got[k]->mount.y, want.mount.y, 1e-12);
    EXPECT_NEAR(got[k]->mount.phi, want.mount.phi, 1e-9);
  }
  EXPECT_FALSE(got[2].has_value());
}
