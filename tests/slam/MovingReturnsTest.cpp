#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "CastScan.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/MovingReturns.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"

using namespace urbanslam;

namespace {

using test::Segment;

// A street along x between facades at y = -8 and y = 8, each building stepping a metre back
// from or forward to the one before (every 13 m on one side, 11 m on the other), lamp posts 25 m
// apart: what tells where along the street a scan was.
std::vector<Segment> street() {
  std::vector<Segment> w;
  for (const auto& [side, length] : {std::pair{1.0, 13.0}, std::pair{-1.0, 11.0}}) {
    double y = 8 * side;
    for (double x = -60; x < 200; x += length) {
      w.push_back({x, y, x + length, y, false});
      const double next = (std::abs(y) > 8.5 ? 8 : 9) * side;
      w.push_back({x + length, y, x + length, next, false});
      y = next;
    }
  }
  for (double x = -50; x < 200; x += 25) {
    const double y0 = 6.8, y1 = 7.0;
    for (const Segment& s : std::vector<Segment>{{x, y0, x + 0.2, y0, false}, {x + 0.2, y0, x + 0.2, y1, false}}) w.push_back(s);
  }
  return w;
}

// A car's outline (4.5 m x 1.8 m) with its rear at x_rear, in the lane centred at y.
void addCar(std::vector<Segment>& w, double x_rear, double y) { test::addBox(w, x_rear, y - 0.9, x_rear + 4.5, y + 0.9, true); }

// A car driving along the street: where its rear is at time 0 and its speed along x (negative:
// the other way), in the lane centred at y.
struct Car {
  double rear_x, speed, lane_y;
};

// One pass along the street at y = -2, a keyframe per metre (10 m/s, 10 Hz) from x_start, the
// cars where they are at each scan (t = 0.1 s per keyframe).
struct Pass {
  std::vector<io::LaserScan> scans;
  std::vector<common::Pose2> poses;
  std::vector<std::vector<bool>> on_car;
};
Pass drive(double x_start, int keyframes, const std::vector<Car>& cars, std::mt19937& rng) {
  Pass p;
  for (int i = 0; i < keyframes; ++i) {
    std::vector<Segment> w = street();
    for (const Car& c : cars) addCar(w, c.rear_x + c.speed * 0.1 * i, c.lane_y);
    p.poses.push_back({x_start + i, -2, 0});
    p.on_car.emplace_back();
    p.scans.push_back(test::castScan(p.poses.back(), w, 1.5, 80, rng, &p.on_car.back()));
  }
  return p;
}
Pass drive(double x_start, int keyframes, double car_rear, double car_speed, double car_y, std::mt19937& rng) {
  return drive(x_start, keyframes, {{car_rear, car_speed, car_y}}, rng);
}

// Of scan i of the pass judged by the scans `by`: the car's returns and the others that were
// hidden, and the car's returns there were.
struct Hidden {
  size_t car = 0, other = 0, car_returns = 0;
};
Hidden judge(const Pass& p, size_t i, const std::vector<size_t>& by, const slam::MovingReturnsOptions& o = {}) {
  std::vector<alignment::BeamFreeSpace> free;
  for (size_t j : by) free.push_back(slam::scanFreeSpace(p.scans[j], o.margin_m, o.margin_fraction));
  std::vector<slam::ScanJudge> judges;
  for (size_t n = 0; n < by.size(); ++n) judges.push_back({&free[n], common::between(p.poses[i], p.poses[by[n]])});
  io::LaserScan s = p.scans[i];
  const size_t n = slam::hideMovingReturns(s, judges, o);
  Hidden h;
  for (size_t b = 0; b < s.size(); ++b) {
    h.car_returns += p.on_car[i][b] ? 1 : 0;
    if (p.scans[i].valid[b] && !s.valid[b]) ++(p.on_car[i][b] ? h.car : h.other);
  }
  EXPECT_EQ(n, h.car + h.other);
  return h;
}

// The map of two passes: the first's keyframes, then the second's first `second_keyframes` (all
// when 0).
std::unique_ptr<slam::Map> twoVisits(const Pass& first, const Pass& second, size_t second_keyframes = 0) {
  auto map = std::make_unique<slam::Map>(nullptr, 1.0);
  for (const Pass* p : {&first, &second}) {
    const size_t count = p == &second && second_keyframes > 0 ? second_keyframes : p->scans.size();
    for (size_t i = 0; i < count; ++i) {
      const size_t k = map->size();
      map->addKeyframe({k, 100.0 * static_cast<double>(p == &second) + 0.1 * static_cast<double>(i), p->poses[i], true, false, {}},
                       io::CompactScan(p->scans[i]));
    }
  }
  return map;
}

// The filter of twoVisits's map: each pass a chain of its true motion, the second pass's
// keyframe 5 placed relative to the first's keyframe 5 `drift_m` short along the street of the
// truth (towards where cars 1.5 m farther ahead would put it), known to half a metre and 3°.
std::unique_ptr<esdf::Esdf> twoVisitsFilter(const Pass& first, const Pass& second, size_t second_keyframes, double drift_m) {
  const common::Pose2 truth = common::between(first.poses[5], second.poses[5]);
  const common::Pose2 drifted{truth.x - drift_m, truth.y, truth.phi};
  auto f = std::make_unique<esdf::Esdf>();
  f->initialise(esdf::toVec(first.poses[0]), esdf::Mat3::Identity() * 1e-9);
  const esdf::Mat3 chain = esdf::Vec3(1e-4, 1e-4, 1e-6).asDiagonal();
  const size_t n = first.poses.size();
  for (size_t i = 1; i < n; ++i)
    f->augmentRelative(i - 1, esdf::toVec(common::between(first.poses[i - 1], first.poses[i])), chain.inverse());
  const esdf::Mat3 jump = esdf::Vec3(0.25, 0.25, std::pow(3 * M_PI / 180, 2)).asDiagonal();
  f->augmentRelative(5, esdf::toVec(common::compose(drifted, common::between(second.poses[5], second.poses[0]))), jump.inverse());
  for (size_t i = 1; i < second_keyframes; ++i)
    f->augmentRelative(n + i - 1, esdf::toVec(common::between(second.poses[i - 1], second.poses[i])), chain.inverse());
  f->recover();
  return f;
}

// An accepted closure within 0.1 m and 0.5° of the true relative pose.
void expectClosureAtTheTruth(const slam::LoopClosureRecord& closure, const common::Pose2& truth) {
  ASSERT_TRUE(closure.accepted) << slam::reasonName(closure.reason);
  const common::Pose2 e = common::between(truth, closure.measurement);
  EXPECT_LT(std::hypot(e.x, e.y), 0.1);
  EXPECT_LT(std::abs(e.phi), 0.5 * M_PI / 180);
}

}  // namespace

// A car driving ahead in the vehicle's lane (slower: it is caught up) and one coming the other
// way: the scans before and after see through where each was. The facades and lamp posts stay;
// a car that stands still is part of the scene.
TEST(MovingReturns, TheReturnsOfACarThatMovedAreHiddenAndTheStreetKept) {
  std::mt19937 rng(3);
  const std::vector<size_t> around = {0, 1, 2, 3, 4, 6, 7, 8, 9, 10};
  for (const auto& [speed, lane] : {std::pair{8.0, -2.0}, std::pair{-8.0, 2.0}}) {
    const Pass p = drive(0, 11, 14, speed, lane, rng);
    const Hidden h = judge(p, 5, around);
    ASSERT_GT(h.car_returns, 10u);
    EXPECT_GE(h.car, h.car_returns * 3 / 4) << "car speed " << speed;
    EXPECT_EQ(h.other, 0u) << "car speed " << speed;
  }
  const Pass parked = drive(0, 11, 14, 0, 2, rng);
  const Hidden h = judge(parked, 5, around);
  ASSERT_GT(h.car_returns, 10u);
  EXPECT_EQ(h.car + h.other, 0u);
}

// The newest keyframe has only the scans before it: an oncoming car is seen through by them (it
// was farther away), one that drives ahead of the vehicle is not (it was nearer).
TEST(MovingReturns, TheNewestScanIsJudgedByTheScansBeforeIt) {
  std::mt19937 rng(4);
  const std::vector<size_t> before = {0, 1, 2, 3, 4};
  const Hidden a = judge(drive(0, 6, 20, -8, 2, rng), 5, before);
  ASSERT_GT(a.car_returns, 10u);
  EXPECT_GE(a.car, a.car_returns * 3 / 4);
  EXPECT_EQ(a.other, 0u);
  const Hidden b = judge(drive(0, 6, 14, 8, -2, rng), 5, before);
  ASSERT_GT(b.car_returns, 10u);
  EXPECT_EQ(b.car + b.other, 0u);
}

// One judge that saw through a return is not enough (a misplaced scan would hide walls). A
// tenth of a second after it the car ahead has moved 0.8 m, within the margin at its range (0.3 m
// and 5 % of 11.5 m); three tenths after, 2.4 m.
TEST(MovingReturns, AReturnSeenThroughByOneJudgeOnlyStays) {
  std::mt19937 rng(5);
  const Pass p = drive(0, 11, 14, 8, -2, rng);
  EXPECT_EQ(judge(p, 5, {6, 8}).car, 0u);
  EXPECT_EQ(judge(p, 5, {8}).car, 0u);
  const Hidden two = judge(p, 5, {8, 9});
  EXPECT_GE(two.car, two.car_returns * 3 / 4);
  slam::MovingReturnsOptions one;
  one.min_views = 1;
  EXPECT_GE(judge(p, 5, {6, 8}, one).car, two.car_returns * 3 / 4);
}

// Two visits of the street, each with a car coming the other way and one driving ahead, which
// the second visit's keyframe sees 1.5 m farther ahead than the first's. With the cars, the
// scans agree best where the cars coincide: 1.5 m off along a street whose facades hardly say
// where along it they were. Without them the steps of the facades and the lamp posts place them.
TEST(MovingReturns, ALoopClosureIsNotAlignedOnTheCarsOfTwoVisits) {
  std::mt19937 rng(6);
  const int n = 11;
  // Keyframe 5 of each pass (t = 0.5 s) at x = 25; there the first's cars are 12 m and 15 m
  // ahead, the second's 13.5 m and 16.5 m.
  const auto cars = [](double ahead) { return std::vector<Car>{{25 + ahead + 8 * 0.5, -8, 2}, {25 + ahead + 3 - 8 * 0.5, 8, -2}}; };
  const Pass first = drive(20, n, cars(12), rng);
  const Pass second = drive(20, n, cars(13.5), rng);
  const common::Pose2 truth = common::between(first.poses[5], second.poses[5]);
  const std::unique_ptr<slam::Map> visits = twoVisits(first, second, n);
  const slam::Map& map = *visits;
  const auto filter = [&] { return twoVisitsFilter(first, second, n, 0.7); };
  // The map's keyframes judged by their neighbours as the estimate places them: the earlier
  // visit's by the scans before and after it (both cars), the newest by those before it only
  // (the oncoming car; the one ahead once the next keyframes are in).
  const auto hidden = [&](size_t k, size_t newest, size_t& others) {
    const io::LaserScan s = slam::MovingReturns({}).scanWithout(map, k, newest, [&](size_t j) { return map.keyframes()[j].pose; });
    const Pass& p = k < static_cast<size_t>(n) ? first : second;
    const std::vector<bool>& on_car = p.on_car[k % static_cast<size_t>(n)];
    size_t car = 0;
    others = 0;
    for (size_t b = 0; b < s.size(); ++b)
      if (p.scans[k % static_cast<size_t>(n)].valid[b] && !s.valid[b]) ++(on_car[b] ? car : others);
    return car;
  };
  const auto car_returns = [](const Pass& p, size_t i) {
    return static_cast<size_t>(std::count(p.on_car[i].begin(), p.on_car[i].end(), true));
  };
  size_t others = 0;
  EXPECT_GE(hidden(5, n + 5, others), car_returns(first, 5) * 3 / 4);
  EXPECT_EQ(others, 0u);
  const size_t newest = hidden(n + 5, n + 5, others);
  EXPECT_EQ(others, 0u);
  const size_t later = hidden(n + 5, 2 * n - 1, others);
  EXPECT_EQ(others, 0u);
  EXPECT_GT(newest, 10u);
  EXPECT_GT(later, newest + 10);
  EXPECT_GE(later, car_returns(second, 5) * 3 / 4);

  slam::LoopClosureOptions with;
  with.min_keyframe_gap = 1;
  slam::LoopClosureOptions without = with;
  without.moving_returns_neighbours = 0;
  auto f0 = filter();
  const auto on_cars = slam::LoopCloser(without).tryClose(*f0, map, 5, n + 5, false);
  ASSERT_TRUE(on_cars.accepted) << slam::reasonName(on_cars.reason);
  EXPECT_GT(std::abs(common::between(truth, on_cars.measurement).x), 1.0);  // a false closure

  auto f1 = filter();
  expectClosureAtTheTruth(slam::LoopCloser(with).tryClose(*f1, map, 5, n + 5, false), truth);
}

// The cars driving ahead of the current keyframe are seen through only by the keyframes after
// it (they moved on): the loop closer judges a keyframe by those the map holds after it too. The
// first visit's two cars stood in the lanes (at the lights: part of that scene, kept); the
// second's drive ahead, each 1.5 m farther on. Judged by the keyframes before it only, the
// second visit's cars stay and align with the first's, 1.5 m off along the street; judged by
// those after it as well, they are hidden and the facades place the scans.
TEST(MovingReturns, TheCurrentKeyframesCarAheadIsJudgedByTheKeyframesAfterIt) {
  std::mt19937 rng(8);
  const size_t n = 11;
  const Pass first = drive(20, static_cast<int>(n), {{25 + 12, 0, -2}, {25 + 15, 0, 2}}, rng);
  const Pass second = drive(20, static_cast<int>(n), {{25 + 13.5 - 8 * 0.5, 8, -2}, {25 + 16.5 - 8 * 0.5, 8, 2}}, rng);
  const common::Pose2 truth = common::between(first.poses[5], second.poses[5]);
  slam::LoopClosureOptions o;
  o.min_keyframe_gap = 1;
  const auto closure = [&](size_t second_keyframes) {
    const std::unique_ptr<slam::Map> map = twoVisits(first, second, second_keyframes);
    auto f = twoVisitsFilter(first, second, second_keyframes, 0.7);
    return slam::LoopCloser(o).tryClose(*f, *map, 5, n + 5, false);
  };
  const auto before_only = closure(6);
  EXPECT_TRUE(before_only.accepted && std::abs(common::between(truth, before_only.measurement).x) > 1.0)  // a false closure
      << slam::reasonName(before_only.reason) << ", " << common::between(truth, before_only.measurement).x << " m off";
  expectClosureAtTheTruth(closure(n), truth);
}

// A car that moved (driving ahead, or coming the other way) leaves returns of the earlier scans
// where the current scan sees through; one that stands does not (the current scan sees it where
// they saw it).
TEST(MovingReturns, AScanThatSeesThroughWhereTheScansBeforeItSawSomethingIsFlagged) {
  std::mt19937 rng(9);
  const auto flagged = [&](double car_speed, double lane) {
    const Pass p = drive(0, 6, 14, car_speed, lane, rng), none;
    const std::unique_ptr<slam::Map> map = twoVisits(p, none);
    return slam::seesThroughEarlier(*map, 5, 5, [&](size_t j) { return map->keyframes()[j].pose; }, {});
  };
  EXPECT_TRUE(flagged(8, -2));  // ahead, slower than the vehicle
  EXPECT_TRUE(flagged(-8, 2));  // coming the other way
  EXPECT_FALSE(flagged(0, 2));  // parked
}

// Global SLAM seeks a flagged keyframe's closures once moving_returns_neighbours keyframes
// follow it (the keyframes after it waiting with it, in order), any other's at once, and the
// ones still waiting at the end of the input.
TEST(MovingReturns, AKeyframeWhoseScanMayHoldACarAheadWaitsForTheKeyframesAfterIt) {
  struct SearchLog : slam::PipelineObserver {
    const slam::Map* map = nullptr;
    std::vector<std::pair<size_t, size_t>> searches;  // keyframe searched, keyframes in the map then
    void onCandidates(const slam::CandidatesEvent& e) override { searches.emplace_back(e.keyframe, map->size()); }
  };
  std::mt19937 rng(10);
  for (const double car_speed : {8.0, 0.0}) {
    const Pass p = drive(0, 12, 14, car_speed, -2, rng);
    slam::PipelineOptions options;
    slam::PipelineStats stats;
    SearchLog log;
    std::vector<slam::PipelineObserver*> observers{&log};
    slam::Map map(std::make_unique<esdf::Esdf>(), 2.0);
    log.map = &map;
    slam::GlobalSlam global(options, map, stats, observers);
    slam::KeyframeConstraint c;
    c.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    for (size_t k = 0; k < p.scans.size(); ++k) {
      c.z = k == 0 ? common::Pose2{} : common::between(p.poses[k - 1], p.poses[k]);
      global.addKeyframe({k, 0.1 * static_cast<double>(k), {}, true, false, {}}, io::CompactScan(p.scans[k]), c);
      global.closeLoops(k, std::chrono::steady_clock::now());
    }
    global.finish();
    const size_t n = p.scans.size(), lag = static_cast<size_t>(options.loop_closure.moving_returns_neighbours);
    ASSERT_EQ(log.searches.size(), n) << car_speed;
    size_t waited = 0;
    for (size_t i = 0; i < n; ++i) {
      EXPECT_EQ(log.searches[i].first, i);  // in order, each once
      if (log.searches[i].second > i + 1) {
        ++waited;
        // A keyframe waits for the keyframes after it (at most lag of them; the end of the input).
        EXPECT_LE(log.searches[i].second, std::min(n, i + lag + 1)) << i;
      }
      if (i + lag < n && slam::seesThroughEarlier(map, i, lag, [&](size_t j) { return p.poses[j]; }, {}))
        EXPECT_EQ(log.searches[i].second, i + lag + 1) << i;
    }
    if (car_speed > 0) {
      EXPECT_GT(waited, n / 2);  // the car ahead is in every scan
    } else {
      EXPECT_EQ(waited, 0u);  // a parked car: every keyframe searched at once
    }
  }
}
