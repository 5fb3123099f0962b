// Alignment covariance (thesis §3.3.3): line variance, Hessian, sampling.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "alignment/SyntheticScan.h"
#include "urbanslam/alignment/AlignmentCovariance.h"
#include "urbanslam/alignment/ScanModel.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;

namespace {
struct Sets {
  ua::PointSet a, b;
  uc::Pose2 truth;
};
Sets make(const ua::test::World& w, const uc::Pose2& pa, const uc::Pose2& pb) {
  ua::test::ScanSpec spec;
  Sets s;
  s.a = ua::pointSetFromScan(ua::test::simulateScan(w, pa, spec), {});
  spec.seed = 3;
  s.b = ua::pointSetFromScan(ua::test::simulateScan(w, pb, spec), {});
  s.truth = uc::between(pa, pb);
  return s;
}
bool positiveDefinite(const Eigen::Matrix3d& C) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
  return C.allFinite() && es.eigenvalues().minCoeff() > 0;
}
}  // namespace

// A corridor along x: the covariance must be large along the corridor, small across it.
TEST(Covariance, CorridorIsUncertainAlongItsAxis) {
  const Sets s = make(ua::test::corridorWorld(), {0, 0, 0}, {0.8, 0.1, 0.05});
  for (auto m : {ua::CovarianceMethod::LineVariance, ua::CovarianceMethod::Hessian}) {
    ua::CovarianceOptions o;
    o.method = m;
    o.hessian_point_to_line = true;
    const Eigen::Matrix3d C = ua::alignmentCovariance(s.a, s.b, s.truth, {}, true, o);
    ASSERT_TRUE(positiveDefinite(C)) << ua::covarianceMethodName(m);
    // Along: metres at least (line variance: tens of metres; the Hessian is the less honest one).
    EXPECT_GT(std::sqrt(C(0, 0)), m == ua::CovarianceMethod::LineVariance ? 10.0 : 1.0) << ua::covarianceMethodName(m);
    EXPECT_LT(std::sqrt(C(1, 1)), 0.05) << ua::covarianceMethodName(m);  // across: centimetres
    EXPECT_GT(C(0, 0), 1e3 * C(1, 1)) << ua::covarianceMethodName(m);
  }
  EXPECT_LT(ua::translationConstraintRatio(s.a, s.b, s.truth, {}), 1e-3);
}

TEST(Covariance, RoomIsWellConstrainedByAllMethods) {
  const Sets s = make(ua::test::roomWorld(), {-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  EXPECT_GT(ua::translationConstraintRatio(s.a, s.b, s.truth, {}), 0.05);
  for (auto m : {ua::CovarianceMethod::LineVariance, ua::CovarianceMethod::Hessian, ua::CovarianceMethod::Sampling}) {
    ua::CovarianceOptions o;
    o.method = m;
    o.samples = 20;
    const Eigen::Matrix3d C = ua::alignmentCovariance(s.a, s.b, s.truth, {}, false, o);
    ASSERT_TRUE(positiveDefinite(C)) << ua::covarianceMethodName(m);
    EXPECT_LT(std::sqrt(C(0, 0)), 0.2) << ua::covarianceMethodName(m);
    EXPECT_LT(std::sqrt(C(1, 1)), 0.2) << ua::covarianceMethodName(m);
    EXPECT_LT(std::sqrt(C(2, 2)), 0.05) << ua::covarianceMethodName(m);
  }
}

// Line variance follows the measurement noise model: more noise, larger covariance.
TEST(Covariance, LineVarianceScalesWithSensorNoise) {
  const auto w = ua::test::roomWorld();
  const auto sa = ua::test::simulateScan(w, {-3, 0, 0.2}), sb = ua::test::simulateScan(w, {-2.2, 0.4, 0.35});
  ua::ScanModelOptions lo, hi;
  hi.range_sigma_m = 4 * lo.range_sigma_m;
  hi.bearing_sigma_rad = 4 * lo.bearing_sigma_rad;
  const uc::Pose2 t = uc::between({-3, 0, 0.2}, {-2.2, 0.4, 0.35});
  ua::CovarianceOptions o;
  o.scale_by_residuals = false;
  const auto Cl = ua::lineVarianceCovariance(ua::IndexedReference(ua::pointSetFromScan(sa, lo)), ua::pointSetFromScan(sb, lo), t, o);
  const auto Ch = ua::lineVarianceCovariance(ua::IndexedReference(ua::pointSetFromScan(sa, hi)), ua::pointSetFromScan(sb, hi), t, o);
  EXPECT_GT(Ch.trace(), 4 * Cl.trace());
}

TEST(Covariance, ParseNames) {
  for (auto m : {ua::CovarianceMethod::LineVariance, ua::CovarianceMethod::Hessian, ua::CovarianceMethod::Sampling})
    EXPECT_EQ(ua::parseCovarianceMethod(ua::covarianceMethodName(m)), m);
  EXPECT_THROW(ua::parseCovarianceMethod("magic"), std::invalid_argument);
}
