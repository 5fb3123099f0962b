// Alignment of real scans (Intel lab, Freiburg corrected log); skipped without the shared data.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <variant>

#include <Eigen/LU>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/io/DataSource.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;
namespace uio = urbanslam::io;

namespace {

struct Log {
  std::vector<uio::LaserScan> scans;
  std::vector<uc::Pose2> refs;
};

const Log* intel() {
  static Log log;
  static bool loaded = false;
  const std::string path = std::string(URBANSLAM_SHARED_DATA_DIR) + "/freiburg_slam_benchmark/corrected_logs/intel-corrected.log.gz";
  if (!loaded) {
    loaded = true;
    if (!std::filesystem::exists(path)) return nullptr;
    auto src = uio::openDataSource(path);
    uio::Measurement m;
    uc::Pose2 last;
    while (src->next(m)) {
      if (auto* r = std::get_if<uio::ReferencePose>(&m))
        last = r->pose;
      else if (auto* s = std::get_if<uio::LaserScan>(&m)) {
        log.scans.push_back(*s);
        log.refs.push_back(last);
      }
    }
  }
  return log.scans.empty() ? nullptr : &log;
}

}  // namespace

// A revisit (scans 65 and 486, 1.4 m and 9 deg apart): CRF+ICP from a 1 m / 25 deg error.
TEST(RealScans, CrfIcpRecoversRevisitFromLargeError) {
  const Log* log = intel();
  if (!log) GTEST_SKIP() << "shared data absent (intel-corrected.log.gz)";
  const uc::Pose2 truth = uc::between(log->refs[65], log->refs[486]);
  ua::AlignerOptions o;
  o.method = ua::Method::CrfIcp;
  const uc::Pose2 guess{truth.x + 0.8, truth.y - 0.6, truth.phi + 25 * M_PI / 180};
  const auto r = ua::align(log->scans[65], log->scans[486], guess, o);
  ASSERT_TRUE(r.converged) << r.failure_reason;
  EXPECT_NEAR(r.transform.x, truth.x, 0.1);
  EXPECT_NEAR(r.transform.y, truth.y, 0.1);
  EXPECT_NEAR(uc::wrapToPi(r.transform.phi - truth.phi), 0.0, M_PI / 180);
  // The covariance is a proper, small one: centimetres, a fraction of a degree.
  EXPECT_GT(r.cov.determinant(), 0);
  EXPECT_LT(std::sqrt(r.cov(0, 0)), 0.1);
  EXPECT_LT(std::sqrt(r.cov(2, 2)), 2 * M_PI / 180);
}

// Consecutive scans (laser odometry): every method from the reference plus a small error.
TEST(RealScans, ConsecutiveScansAllMethods) {
  const Log* log = intel();
  if (!log) GTEST_SKIP() << "shared data absent (intel-corrected.log.gz)";
  for (auto method : {ua::Method::Icp, ua::Method::PlIcp, ua::Method::CrfIcp}) {
    ua::AlignerOptions o;
    o.method = method;
    for (int a : {403, 416, 850}) {
      const uc::Pose2 truth = uc::between(log->refs[a], log->refs[a + 1]);
      const auto r = ua::align(log->scans[a], log->scans[a + 1], {truth.x + 0.1, truth.y - 0.1, truth.phi + 0.05}, o);
      EXPECT_TRUE(r.converged) << ua::methodName(method) << " " << a << ": " << r.failure_reason;
      EXPECT_NEAR(r.transform.x, truth.x, 0.1) << ua::methodName(method) << " " << a;
      EXPECT_NEAR(r.transform.y, truth.y, 0.1) << ua::methodName(method) << " " << a;
      EXPECT_NEAR(uc::wrapToPi(r.transform.phi - truth.phi), 0.0, M_PI / 180) << ua::methodName(method) << " " << a;
    }
  }
}
