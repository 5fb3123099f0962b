// Trajectory error against ground truth: the closed-form rigid alignment against a brute-force
// search over the rotation angle (for a fixed angle the best translation is the mean offset),
// and the reference-pose readers.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "TestUtil.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/TrajectoryError.h"

namespace urbanslam::esdf {
namespace {

// RMSE and mean heading error at rotation theta with the best translation for that theta.
void errorsAt(const std::vector<PoseGraphVertex>& est, const std::vector<PoseGraphVertex>& ref, double theta, double* rmse,
              double* heading) {
  const double c = std::cos(theta), s = std::sin(theta);
  double mx = 0, my = 0;
  for (size_t k = 0; k < est.size(); ++k) {
    mx += ref[k].pose.x() - (c * est[k].pose.x() - s * est[k].pose.y());
    my += ref[k].pose.y() - (s * est[k].pose.x() + c * est[k].pose.y());
  }
  mx /= est.size();
  my /= est.size();
  double sum2 = 0, sum_h = 0;
  for (size_t k = 0; k < est.size(); ++k) {
    const double dx = c * est[k].pose.x() - s * est[k].pose.y() + mx - ref[k].pose.x();
    const double dy = s * est[k].pose.x() + c * est[k].pose.y() + my - ref[k].pose.y();
    sum2 += dx * dx + dy * dy;
    sum_h += std::fabs(std::remainder(est[k].pose.z() + theta - ref[k].pose.z(), 2 * M_PI));
  }
  *rmse = std::sqrt(sum2 / est.size());
  *heading = sum_h / est.size();
}

TEST(TrajectoryError, MatchesBruteForceAlignment) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<PoseGraphVertex> ref, est;
    const Vec3 gauge = test::randomPose(rng, 50.0);  // the estimate's frame, arbitrary
    for (long k = 0; k < 200; ++k) {
      const Vec3 truth = test::randomPose(rng, 30.0);
      ref.push_back({k, truth});
      const Vec3 noisy = truth + Vec3(test::gauss(rng, 0.3), test::gauss(rng, 0.3), test::gauss(rng, 0.05));
      est.push_back({k, compose(gauge, noisy)});
    }
    const TrajectoryError e = trajectoryError(est, ref);
    // Brute force: a fine grid over the angle, then ternary refinement around the best cell.
    double best = 1e300, best_theta = 0, rmse, heading;
    for (int i = 0; i < 3600; ++i) {
      const double th = -M_PI + i * 2 * M_PI / 3600;
      errorsAt(est, ref, th, &rmse, &heading);
      if (rmse < best) best = rmse, best_theta = th;
    }
    double lo = best_theta - 2 * M_PI / 3600, hi = best_theta + 2 * M_PI / 3600;
    for (int it = 0; it < 100; ++it) {
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      double r1, r2;
      errorsAt(est, ref, m1, &r1, &heading);
      errorsAt(est, ref, m2, &r2, &heading);
      (r1 < r2 ? hi : lo) = r1 < r2 ? m2 : m1;
    }
    errorsAt(est, ref, 0.5 * (lo + hi), &rmse, &heading);
    EXPECT_EQ(e.matched, 200u);
    EXPECT_NEAR(e.ate_rmse_m, rmse, 1e-9);
    EXPECT_NEAR(e.heading_mean_abs_rad, heading, 1e-7);
    EXPECT_NEAR(std::remainder(e.alignment.z() - 0.5 * (lo + hi), 2 * M_PI), 0.0, 1e-7);
  }
}

TEST(TrajectoryError, MatchesByIdAndNeedsTwoCommonIds) {
  const std::vector<PoseGraphVertex> ref{{0, Vec3(0, 0, 0)}, {1, Vec3(1, 0, 0)}, {2, Vec3(2, 0, 0)}};
  // Estimate in another order, with an id the reference does not have.
  const std::vector<PoseGraphVertex> est{
      {2, Vec3(0, 2, M_PI / 2)}, {7, Vec3(5, 5, 0)}, {0, Vec3(0, 0, M_PI / 2)}, {1, Vec3(0, 1, M_PI / 2)}};
  const TrajectoryError e = trajectoryError(est, ref);
  EXPECT_EQ(e.matched, 3u);
  EXPECT_NEAR(e.ate_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(e.heading_mean_abs_rad, 0.0, 1e-12);
  EXPECT_THROW(trajectoryError({{5, Vec3::Zero()}, {0, Vec3::Zero()}}, ref), common::InputError);
}

TEST(TrajectoryError, ReadsTextAndG2oReferences) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string with_ids = (dir / "urbanslam_ref_ids.txt").string();
  const std::string no_ids = (dir / "urbanslam_ref_noids.dat").string();
  const std::string g2o = (dir / "urbanslam_ref.g2o").string();
  const std::string bad = (dir / "urbanslam_ref_bad.txt").string();
  std::ofstream(with_ids) << "3 1.0 2.0 0.5\n\n4 2.0 3.0 -0.5\n";
  std::ofstream(no_ids) << "1.0 2.0 0.5\n2.0 3.0 -0.5\n";
  std::ofstream(g2o) << "VERTEX_SE2 3 1.0 2.0 0.5\nVERTEX_SE2 4 2.0 3.0 -0.5\n";
  std::ofstream(bad) << "1.0 2.0\n";
  const auto a = readReferencePoses(with_ids), b = readReferencePoses(no_ids), c = readReferencePoses(g2o);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(a[1].id, 4);
  EXPECT_EQ(b[1].id, 1);
  EXPECT_EQ(c[0].id, 3);
  EXPECT_EQ(a[1].pose, c[1].pose);
  EXPECT_EQ(a[1].pose, b[1].pose);
  EXPECT_THROW(readReferencePoses(bad), common::InputError);
  for (const auto& p : {with_ids, no_ids, g2o, bad}) std::filesystem::remove(p);
}

}  // namespace
}  // namespace urbanslam::esdf
