// A run folder evaluated as `urbanslam eval` does, against figures computed here by hand: a run
// that is the reference moved rigidly scores zero; a run with one pose off by a known amount
// scores that amount on the relations that touch it, and is refused when nothing overlaps.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/evaluation/RunReport.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::evaluation {
namespace {

namespace test = urbanslam::test;

namespace fs = std::filesystem;

std::vector<io::StampedPose> square(const common::Pose2& frame) {
  std::vector<io::StampedPose> path;
  for (int i = 0; i < 40; ++i) {
    const double s = 0.5 * i;  // along a 5 m square, 10 poses per side
    const int side = (i / 10) % 4;
    const double u = std::fmod(s, 5.0);
    const common::Pose2 p = side == 0   ? common::Pose2{u, 0, 0}
                            : side == 1 ? common::Pose2{5, u, M_PI / 2}
                            : side == 2 ? common::Pose2{5 - u, 5, M_PI}
                                        : common::Pose2{0, 5 - u, -M_PI / 2};
    path.push_back({100.0 + i, common::compose(frame, p)});
  }
  return path;
}

fs::path runFolder(const std::string& name, const std::vector<io::StampedPose>& poses) {
  const fs::path dir = test::scratchDir("runreport_" + name);
  io::writeTum((dir / "trajectory_odometry.tum").string(), poses);
  io::writeTum((dir / "trajectory_scans.tum").string(), poses);
  return dir;
}

// Relations between consecutive poses of the reference (t1 t2 x y z roll pitch yaw).
std::string relationsFile(const fs::path& dir, const std::vector<io::StampedPose>& ref) {
  const std::string path = (dir / "ref.relations").string();
  std::ofstream f(path);
  f.precision(12);
  for (size_t i = 1; i < ref.size(); ++i) {
    const common::Pose2 d = common::between(ref[i - 1].pose, ref[i].pose);
    f << ref[i - 1].timestamp << " " << ref[i].timestamp << " " << d.x << " " << d.y << " 0 0 0 " << d.phi << "\n";
  }
  return path;
}

TEST(RunReport, ARigidlyMovedReferenceScoresZero) {
  const auto ref = square({});
  const fs::path dir = runFolder("rigid", square({3.0, -2.0, 0.7}));
  io::writeTum((dir / "reference.tum").string(), ref);
  RunReportOptions o;
  o.run_dir = dir.string();
  o.reference = (dir / "reference.tum").string();
  o.relations = relationsFile(dir, ref);
  o.time_offset_s = 0.0;
  const RunReport r = evaluateRun(o);
  const std::string j = r.json.dump();
  EXPECT_NEAR(r.json.at("ate_rmse_m").asNumber(), 0.0, 1e-6) << j;
  EXPECT_EQ(r.json.at("matched").asNumber(), 40) << j;
  EXPECT_NEAR(r.json.at("relations").at("abs_trans_mean_m").asNumber(), 0.0, 1e-6) << j;
  EXPECT_EQ(r.json.at("relations").at("used").asNumber(), 39) << j;
  EXPECT_EQ(r.aligned.size(), 40u);
}

TEST(RunReport, OnePoseOffShowsOnTheRelationsThatTouchIt) {
  const auto ref = square({});
  auto run = ref;
  run[20].pose.y += 0.3;  // one pose 0.3 m off, sideways
  const fs::path dir = runFolder("onepose", run);
  RunReportOptions o;
  o.run_dir = dir.string();
  o.relations = relationsFile(dir, ref);
  o.time_offset_s = 0.0;
  const RunReport r = evaluateRun(o);
  // Two of the 39 relations touch pose 20, each off by 0.3 m in translation.
  EXPECT_NEAR(r.json.at("relations").at("abs_trans_mean_m").asNumber(), 2 * 0.3 / 39, 1e-6) << r.json.dump();
  EXPECT_TRUE(r.aligned.empty());  // no reference given: no ATE, no plots
}

TEST(RunReport, NoOverlapIsAnInputError) {
  const auto ref = square({});
  const fs::path dir = runFolder("nooverlap", ref);
  auto later = ref;
  for (auto& p : later) p.timestamp += 1000;
  io::writeTum((dir / "later.tum").string(), later);
  RunReportOptions o;
  o.run_dir = dir.string();
  o.reference = (dir / "later.tum").string();
  EXPECT_THROW(evaluateRun(o), common::InputError);
  o.run_dir = (dir / "absent").string();
  EXPECT_THROW(evaluateRun(o), common::InputError);
}

}  // namespace
}  // namespace urbanslam::evaluation
