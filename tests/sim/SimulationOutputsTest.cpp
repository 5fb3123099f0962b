// A whole small drive: reproducible to the byte, readable by the project's own reader, and
// consistent with the simulator's ground truth.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/sim/SimulationOutputs.h"

using namespace urbanslam;
using namespace urbanslam::sim;

namespace {

SimOptions smallDrive() {
  SimOptions o;
  o.city.seed = 11;
  o.city.area_km2 = 0.3;
  o.route.route_length_km = 0.4;
  o.gps.enabled = true;
  return o;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

TEST(SimulationOutputs, SameSeedGivesByteIdenticalOutputs) {
  const auto d1 = test::scratchDir("sim_same_1"), d2 = test::scratchDir("sim_same_2");
  const auto s1 = writeSimulation(smallDrive(), d1.string(), "");
  const auto s2 = writeSimulation(smallDrive(), d2.string(), "");
  EXPECT_GT(s1.scans, 300u);
  EXPECT_EQ(s1.measurements, s2.measurements);
  for (const char* f : {"city.rawlog", "truth.tum", "loops.csv", "walls.csv", "walls.png"}) {
    const std::string a = slurp((d1 / f).string()), b = slurp((d2 / f).string());
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_TRUE(a == b) << f << " differs between two runs with the same seed";
  }
  // A different seed is a different drive.
  SimOptions other = smallDrive();
  other.city.seed = 12;
  const auto d3 = test::scratchDir("sim_same_3");
  writeSimulation(other, d3.string(), "");
  EXPECT_NE(slurp((d1 / "truth.tum").string()), slurp((d3 / "truth.tum").string()));
}

// Without the rawlog the ground truth must be the very same bytes: a run that streamed the
// simulation is scored against it.
TEST(SimulationOutputs, TruthWithoutRawlogIsByteIdenticalToAFullRun) {
  for (const bool camera : {false, true}) {
    SimOptions o = smallDrive();
    if (camera) {
      o.route.route_length_km = 0.15;
      o.camera.enabled = true;
      o.camera.rate_hz = 1.0;
    }
    const auto full = test::scratchDir(camera ? "sim_full_cam" : "sim_full");
    const auto truth = test::scratchDir(camera ? "sim_truth_cam" : "sim_truth");
    const auto s1 = writeSimulation(o, full.string(), "[city]\nseed = 11\n");
    const auto s2 = writeSimulation(o, truth.string(), "[city]\nseed = 11\n", {}, false);
    EXPECT_EQ(s1.scans, s2.scans);
    EXPECT_EQ(s1.loop_pairs, s2.loop_pairs);
    EXPECT_TRUE(std::filesystem::exists(full / "city.rawlog"));
    EXPECT_FALSE(std::filesystem::exists(truth / "city.rawlog"));
    EXPECT_FALSE(std::filesystem::exists(truth / "city_Images"));
    std::vector<std::string> files = {"truth.tum", "loops.csv", "walls.csv", "walls.png", "config.ini"};
    if (camera) files.insert(files.end(), {"image_loops.csv", "image_loops.txt"});
    for (const std::string& f : files) {
      const std::string a = slurp((full / f).string()), b = slurp((truth / f).string());
      EXPECT_FALSE(a.empty()) << f;
      EXPECT_TRUE(a == b) << f << " differs without the rawlog (camera " << camera << ")";
    }
  }
}

TEST(SimulationOutputs, RawlogReadsBackWithTheProjectReader) {
  const auto dir = test::scratchDir("sim_readback");
  const SimOptions o = smallDrive();
  const auto sum = writeSimulation(o, dir.string(), "");

  // Reference: the same measurements straight from the simulator.
  SimulatedSource sim(o);
  auto file = io::openDataSource((dir / "city.rawlog").string());
  io::Measurement a, b;
  size_t scans = 0, odometry = 0, gps = 0, refs = 0, n = 0;
  while (sim.next(a)) {
    ASSERT_TRUE(file->next(b)) << "rawlog ends early at " << n;
    ASSERT_EQ(a.index(), b.index()) << n;
    EXPECT_NEAR(io::timestampOf(a), io::timestampOf(b), 1e-5) << n;
    if (const auto* sa = std::get_if<io::LaserScan>(&a)) {
      const auto& sb = std::get<io::LaserScan>(b);
      ASSERT_EQ(sa->size(), sb.size());
      EXPECT_NEAR(sa->angle_min_rad, sb.angle_min_rad, 1e-6);
      EXPECT_NEAR(sa->angle_increment_rad, sb.angle_increment_rad, 1e-6);
      EXPECT_NEAR(sa->sensor_pose.x, sb.sensor_pose.x, 1e-6);
      for (size_t i = 0; i < sa->size(); ++i) {
        ASSERT_EQ(sa->valid[i], sb.valid[i]) << n << " beam " << i;
        if (sa->valid[i]) {
          ASSERT_NEAR(sa->ranges[i], sb.ranges[i], 1e-4);
        }
      }
      ++scans;
    } else if (const auto* oa = std::get_if<io::OdometryReading>(&a)) {
      const auto& ob = std::get<io::OdometryReading>(b);
      EXPECT_NEAR(oa->pose.x, ob.pose.x, 1e-4);
      EXPECT_NEAR(oa->pose.y, ob.pose.y, 1e-4);
      EXPECT_NEAR(common::wrapToPi(oa->pose.phi - ob.pose.phi), 0, 1e-5);
      ++odometry;
    } else if (std::holds_alternative<io::GpsFix>(a)) {
      ++gps;
    } else if (const auto* ra = std::get_if<io::ReferencePose>(&a)) {
      EXPECT_NEAR(ra->pose.x, std::get<io::ReferencePose>(b).pose.x, 1e-4);
      ++refs;
    }
    ++n;
  }
  EXPECT_FALSE(file->next(b));
  EXPECT_EQ(scans, sum.scans);
  EXPECT_EQ(odometry, sum.odometry);
  EXPECT_EQ(refs, sum.scans);
  EXPECT_GT(gps, 0u);
  // Scan rate and odometry rate as configured, over the simulated duration.
  EXPECT_NEAR(static_cast<double>(scans), sum.duration_s * o.laser.rate_hz, 1.5);
  EXPECT_NEAR(static_cast<double>(odometry), sum.duration_s * o.odometry.rate_hz, 1.5);

  // truth.tum: one pose per scan, at the scan times.
  const auto truth = io::readTum((dir / "truth.tum").string());
  EXPECT_EQ(truth.size(), sum.scans);
}

TEST(SimulationOutputs, CameraImagesAreStoredBesideTheRawlogAndReadBackPixelForPixel) {
  const auto dir = test::scratchDir("sim_camera");
  SimOptions o = smallDrive();
  o.route.route_length_km = 0.15;
  o.laser.enabled = false;
  o.camera.enabled = true;
  o.camera.rate_hz = 1.0;
  const auto sum = writeSimulation(o, dir.string(), "");
  ASSERT_GT(sum.images, 10u);
  EXPECT_EQ(sum.scans, 0u);
  EXPECT_NEAR(static_cast<double>(sum.images), sum.duration_s * o.camera.rate_hz, 1.5);
  // External images: one PNG each, a rawlog that holds only their names.
  size_t files = 0;
  for (const auto& f : std::filesystem::directory_iterator(dir / "city_Images")) files += f.path().extension() == ".png";
  EXPECT_EQ(files, sum.images);
  EXPECT_LT(std::filesystem::file_size(dir / "city.rawlog"), 640u * 480u);  // less than one image embedded

  // Reference: the images straight from the simulator.
  SimulatedSource sim(o);
  auto file = io::openDataSource((dir / "city.rawlog").string());
  io::Measurement a, b;
  size_t images = 0, refs = 0;
  while (sim.next(a)) {
    ASSERT_TRUE(file->next(b));
    ASSERT_EQ(a.index(), b.index());
    refs += std::holds_alternative<io::ReferencePose>(a);
    if (const auto* ia = std::get_if<io::CameraImage>(&a)) {
      const auto& ib = std::get<io::CameraImage>(b);
      EXPECT_EQ(ib.label, "CAMERA");
      ASSERT_EQ(ib.width, ia->width);
      ASSERT_EQ(ib.height, ia->height);
      EXPECT_TRUE(*ia->pixels == *ib.pixels) << "image " << images;
      char name[32];
      std::snprintf(name, sizeof name, "CAMERA_%06zu.png", images);
      EXPECT_EQ(std::filesystem::path(ib.source).filename().string(), name);
      ++images;
    }
  }
  EXPECT_FALSE(file->next(b));
  EXPECT_EQ(images, sum.images);
  EXPECT_EQ(refs, sum.images);  // without a laser, the truth is given at the image times
  EXPECT_EQ(io::readTum((dir / "truth.tum").string()).size(), sum.images);
  EXPECT_TRUE(std::filesystem::exists(dir / "image_loops.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "image_loops.txt"));
}

TEST(SimulationOutputs, OdometryDriftsFromTheTruthOnlyAsMuchAsItsNoise) {
  // Noise-free odometry reproduces the true path (chained increments of the true motion).
  SimOptions o = smallDrive();
  o.odometry.sigma_per_m = o.odometry.sigma_per_rad = o.odometry.sigma_phi_per_m_rad = 0;
  o.odometry.scale_bias = o.odometry.steering_bias_deg = o.odometry.slip_probability = 0;
  o.odometry.rate_hz = 100;
  o.laser.rate_hz = 1;
  SimulatedSource sim(o);
  io::Measurement m;
  common::Pose2 odo, start;
  bool first = true;
  double worst = 0;
  while (sim.next(m)) {
    if (const auto* r = std::get_if<io::OdometryReading>(&m)) odo = r->pose;
    if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
      if (first) start = ref->pose, first = false;
      const common::Pose2 rel = common::between(start, ref->pose);  // truth in the odometry frame
      worst = std::max(worst, std::hypot(rel.x - odo.x, rel.y - odo.y));
    }
  }
  EXPECT_LT(worst, 0.05);  // 400 m of chord-approximated arcs at 100 Hz
}

TEST(SimOptions, UnknownKeysAndOutOfRangeValuesNameFileSectionAndKey) {
  const auto dir = test::scratchDir("sim_options");
  const std::string bad_key = (dir / "bad_key.ini").string(), bad_value = (dir / "bad_value.ini").string();
  std::ofstream(bad_key) << "[city]\nseeed = 3\n";
  std::ofstream(bad_value) << "[city]\narea_km2 = 500\n";
  try {
    loadSimOptions(bad_key);
    FAIL() << "unknown key accepted";
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_key.ini"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[city] seeed"), std::string::npos) << e.what();
  }
  try {
    loadSimOptions(bad_value);
    FAIL() << "out-of-range value accepted";
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("area_km2"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(loadSimOptions(test::repoPath("ini/city-1km2.ini")));
}
