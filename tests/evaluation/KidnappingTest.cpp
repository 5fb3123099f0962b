// The kidnapping splice against poses computed by hand: a robot driving along x at 1 m/s with
// odometry that drifts by a known transform, cut at t1 and resumed at t2.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "urbanslam/evaluation/Kidnapping.h"

using namespace urbanslam;

namespace {

// Odometry at 10 Hz and a scan each second over 100 s; the odometry frame is turned by 0.3 rad
// and shifted, so moving it is not the identity.
std::vector<io::Measurement> straightDrive() {
  std::vector<io::Measurement> log;
  const common::Pose2 frame{5.0, -2.0, 0.3};
  for (int k = 0; k <= 1000; ++k) {
    const double t = 0.1 * k;
    log.push_back(io::OdometryReading{t, common::compose(frame, {t, 0.0, 0.0})});
    if (k % 10 == 0) {
      io::LaserScan s;
      s.timestamp = t;
      log.push_back(s);
    }
  }
  return log;
}

}  // namespace

TEST(Kidnapping, TheSecondPieceFollowsTheFirstInTimeAndOdometry) {
  const auto log = straightDrive();
  const auto out = evaluation::spliceKidnapping(log, 30.0, 70.0, 10.0, 20.0);
  ASSERT_FALSE(out.empty());
  double last_t = -1;
  std::optional<common::Pose2> last_odometry;
  for (const auto& m : out) {
    const double t = io::timestampOf(m);
    EXPECT_GE(t, 20.0 - 1e-9);
    EXPECT_LE(t, 50.0 + 1e-9);
    EXPECT_GE(t, last_t);  // still in time order
    last_t = t;
    if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
      // The odometry moves on by 0.1 m per reading, turned by nothing, across the cut as well:
      // the wheels felt nothing of the jump.
      if (last_odometry) {
        const common::Pose2 step = common::between(*last_odometry, od->pose);
        // t2's reading, moved to t1, continues from the last before t1 (29.9 s) where it was.
        const double expected = t >= 30.0 && t < 30.05 ? 0.0 : 0.1;
        EXPECT_NEAR(step.x, expected, 1e-9) << t;
        EXPECT_NEAR(step.y, 0.0, 1e-9) << t;
        EXPECT_NEAR(step.phi, 0.0, 1e-12) << t;
      }
      last_odometry = od->pose;
    }
  }
  // Scans: 20..29 from the first piece, then 70..90 moved to 30..50.
  size_t scans = 0;
  for (const auto& m : out) scans += std::holds_alternative<io::LaserScan>(m);
  EXPECT_EQ(scans, 10u + 21u);
}

TEST(Kidnapping, JumpsStartEvenlyAndEndFarEnoughAndLateEnough) {
  // A robot tracked every second for 200 s, along x at 1 m/s.
  std::vector<io::StampedPose> tracked;
  for (int k = 0; k <= 200; ++k) tracked.push_back({static_cast<double>(k), {static_cast<double>(k), 0.0, 0.0}});
  evaluation::KidnapSchedule s;
  s.count = 4;
  s.before_s = 10, s.after_s = 20, s.gap_s = 30, s.min_jump_m = 45;
  const auto jumps = evaluation::pickKidnapJumps(tracked, 0.0, 200.0, s);
  ASSERT_EQ(jumps.size(), 4u);
  // Starts in [10, 150] (141 of them) at the middles of four equal parts: indices 17, 52, 88, 123.
  const size_t starts[] = {10 + 17, 10 + 52, 10 + 88, 10 + 123};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(jumps[k].from, starts[k]);
    EXPECT_EQ(jumps[k].to, starts[k] + 45);  // 45 m away comes after the 30 s gap
  }
}
