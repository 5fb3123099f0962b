// A laser and a camera on one car, localized in the map of the first half of its drive after
// being carried elsewhere (simulated kidnappings in the second half). Checked against the
// simulator's truth: with the camera's images the localizer finds the new place within 3 s more
// often than with the scans alone, and neither ever takes a wrong place.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "LaserCameraCity.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/evaluation/Kidnapping.h"
#include "urbanslam/io/MemorySource.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

std::vector<slam::LocalizedScan> localize(const slam::Pipeline& map, const std::vector<io::Measurement>& log, const common::Pose2& initial,
                                          bool images, slam::LocalizerStats& stats) {
  slam::LocalizerOptions o = slam::localizerOptions(map.options());
  o.images.enabled = images;
  slam::Localizer loc(map.map(), map.options(), o);
  loc.setInitialPose(initial);
  io::MemorySource source(log);
  std::vector<slam::LocalizedScan> scans = slam::localizeInMaps({&loc}, source, nullptr, &map.options()).scans;
  stats = loc.stats();
  return scans;
}

}  // namespace

TEST(ImagePlacesCity, TheCameraFindsKidnappedVehiclesThatTheScansAloneDoNot) {
  const sim::SimOptions so = test::laserCameraCity();
  const slam::PipelineOptions po = test::laserCameraPipeline();

  // The drive in memory; the first half mapped (the truth kept apart).
  std::vector<io::Measurement> log;
  std::vector<io::StampedPose> truth;
  size_t scans = 0;
  {
    sim::SimulatedSource src(so);
    for (io::Measurement m; src.next(m);) {
      if (const auto* r = std::get_if<io::ReferencePose>(&m)) {
        truth.push_back({r->timestamp, r->pose});
        continue;
      }
      scans += std::holds_alternative<io::LaserScan>(m);
      log.push_back(std::move(m));
    }
  }
  size_t half = 0;
  for (size_t seen = 0; seen < scans / 2; ++half) seen += std::holds_alternative<io::LaserScan>(log[half]);
  const std::vector<io::Measurement> first(log.begin(), log.begin() + static_cast<long>(half));
  const std::vector<io::Measurement> second(log.begin() + static_cast<long>(half), log.end());
  log.clear();
  slam::Pipeline map(po);
  {
    io::MemorySource source(first);
    map.run(source);
    map.finish();
  }
  ASSERT_GT(map.stats().image_keyframes, 50u);

  // The truth in the map's frame (by the first keyframe; the map is a tenth of a metre right).
  const auto trueAt = [&](double t) {
    common::Pose2 g;
    EXPECT_TRUE(evaluation::interpolatePose(truth, t, 0.2, g)) << t;
    return g;
  };
  const slam::Keyframe& k0 = map.keyframes().front();
  const common::Pose2 map_from_truth = common::compose(k0.pose, common::inverse(trueAt(k0.timestamp)));
  const auto right = [&](const slam::LocalizedScan& r, double truth_time) {
    const common::Pose2 d = common::between(common::compose(map_from_truth, trueAt(truth_time)), r.pose);
    return std::hypot(d.x, d.y) <= 0.5 && std::abs(d.phi) <= 10 * M_PI / 180;
  };

  // The second half uninterrupted, with the scans alone: the jumps' ends are scans it tracked.
  slam::LocalizerStats stats;
  const std::vector<slam::LocalizedScan> ref = localize(map, second, map.scanTrajectory().back().pose, false, stats);
  std::vector<io::StampedPose> tracked;
  for (const auto& r : ref)
    if (r.state == slam::LocalizationState::Tracking && right(r, r.timestamp)) tracked.push_back({r.timestamp, r.pose});
  evaluation::KidnapSchedule schedule;
  schedule.count = 6;
  const auto jumps = evaluation::pickKidnapJumps(tracked, io::timestampOf(second.front()), io::timestampOf(second.back()), schedule);
  ASSERT_GE(jumps.size(), 4u);

  int within_3s[2] = {0, 0};
  size_t image_fixes = 0;
  for (const auto& j : jumps) {
    const double t1 = tracked[j.from].timestamp, t2 = tracked[j.to].timestamp;
    const std::vector<io::Measurement> spliced = evaluation::spliceKidnapping(second, t1, t2, schedule.before_s, schedule.after_s);
    ASSERT_FALSE(spliced.empty());
    common::Pose2 initial;
    for (const auto& r : ref)
      if (r.timestamp >= t1 - schedule.before_s) {
        initial = r.pose;
        break;
      }
    for (const bool images : {false, true}) {
      const std::vector<slam::LocalizedScan> run = localize(map, spliced, initial, images, stats);
      double found = HUGE_VAL;
      for (const auto& r : run) {
        if (r.timestamp < t1 || r.state != slam::LocalizationState::Tracking) continue;
        const bool ok = right(r, r.timestamp + t2 - t1);
        // A place taken after the jump is the true one.
        EXPECT_TRUE(!r.relocalised || ok) << "jump " << t1 << " -> " << t2 << (images ? " with" : " without") << " images, fix at "
                                          << r.timestamp;
        if (ok) found = std::min(found, r.timestamp - t1);
      }
      within_3s[images] += found <= 3.0;
      if (images) image_fixes += stats.image_relocalisations;
    }
  }
  std::cout << jumps.size() << " jumps, within 3 s: " << within_3s[0] << " with the scans alone, " << within_3s[1] << " with the camera ("
            << image_fixes << " fixes near the image's places)\n";
  EXPECT_GT(within_3s[1], within_3s[0]);
  EXPECT_GE(within_3s[1], 2);
  EXPECT_GT(image_fixes, 0u);
}
