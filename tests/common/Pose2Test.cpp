#include <gtest/gtest.h>

#include <random>

#include "urbanslam/common/Pose2.h"

using namespace urbanslam::common;

TEST(Pose2, BetweenInvertsCompose) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5), a(-M_PI, M_PI);
  for (int i = 0; i < 100; ++i) {
    const Pose2 p{u(rng), u(rng), a(rng)}, q{u(rng), u(rng), a(rng)};
    const Pose2 d = between(p, q);
    const Pose2 q2 = compose(p, d);
    EXPECT_NEAR(q2.x, q.x, 1e-12);
    EXPECT_NEAR(q2.y, q.y, 1e-12);
    EXPECT_NEAR(wrapToPi(q2.phi - q.phi), 0, 1e-12);
    const Pose2 e = compose(p, inverse(p));
    EXPECT_NEAR(e.x, 0, 1e-12);
    EXPECT_NEAR(e.y, 0, 1e-12);
    EXPECT_NEAR(e.phi, 0, 1e-12);
  }
}

TEST(Pose2, ComposeByHand) {
  const Pose2 r = compose({1, 2, M_PI / 2}, {1, 0, M_PI / 2});
  EXPECT_NEAR(r.x, 1, 1e-12);
  EXPECT_NEAR(r.y, 3, 1e-12);
  EXPECT_NEAR(r.phi, M_PI, 1e-12);
  EXPECT_NEAR(wrapToPi(3 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrapToPi(-M_PI), M_PI, 1e-12);
}
