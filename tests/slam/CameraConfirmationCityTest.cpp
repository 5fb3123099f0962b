// A laser and a camera on one car: closures measured by the scans are confirmed by the camera
// where the images nearest their two keyframes measure the same full relative pose. Checked
// against the simulator's truth: a small city's drive with the shipped pipeline must have
// closures confirmed that way, and each of them must measure the true relative pose.
#include <gtest/gtest.h>

#include <cmath>

#include "LaserCameraCity.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

TEST(CameraConfirmationCity, ClosuresConfirmedByTheCameraMeasureTheTruePose) {
  slam::Pipeline p(test::laserCameraPipeline());
  sim::SimulatedSource src(test::laserCameraCity());
  p.runInput(src);
  p.finish(src);
  ASSERT_GT(p.stats().image_keyframes, 100u);

  const auto truth = [&](double t) {
    common::Pose2 pose;
    EXPECT_TRUE(evaluation::interpolatePose(p.referenceTrajectory(), t, 0.2, pose)) << t;
    return pose;
  };
  size_t by_camera = 0, by_closure = 0;
  for (const auto& c : p.loopClosures()) {
    if (!c.accepted) continue;
    by_camera += c.confirmed_by == slam::Confirmation::Camera;
    by_closure += c.confirmed_by == slam::Confirmation::Closure;
    // Every accepted closure measures the true relative pose (the confirmation tolerance).
    const common::Pose2 d = common::between(common::between(truth(c.from_time), truth(c.to_time)), c.measurement);
    EXPECT_LT(std::hypot(d.x, d.y), 0.3) << c.from << " -> " << c.to << " " << slam::confirmationName(c.confirmed_by);
    EXPECT_LT(std::abs(d.phi), 3 * M_PI / 180) << c.from << " -> " << c.to << " " << slam::confirmationName(c.confirmed_by);
  }
  EXPECT_GE(by_camera, 10u);
  EXPECT_GE(by_closure, 10u);
}
