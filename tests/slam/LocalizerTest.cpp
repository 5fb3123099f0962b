// Localization in a frozen map, checked against references independent of the localizer: the
// benchmark relations of the FR079 excerpt (Kümmerle et al. 2009) and the trajectory of a
// mapping run over the whole excerpt. The map is built from the excerpt's first 600 scans; the
// other 600 are localized in it. They start where the map ended, leave it for a room the first
// half never saw (about 1350-1430 s and again after 1460 s) and come back in between.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "SkippingSource.h"
#include "TestPaths.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/slam/LocalizationSmoothing.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

constexpr size_t kMappedScans = 600;

std::string excerpt() { return test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"); }

struct Maps {
  std::unique_ptr<slam::Pipeline> first;  // the first kMappedScans scans
  std::unique_ptr<slam::Pipeline> full;   // every scan: the reference trajectory
  size_t skip = 0;                        // measurements of the first part
};

const Maps& maps() {
  static const Maps m = [] {
    Maps m;
    const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
    m.first = std::make_unique<slam::Pipeline>(o);
    auto src = io::openDataSource(excerpt());
    while (m.first->stats().scans < kMappedScans && m.first->step(*src)) {
    }
    m.first->finish();
    m.skip = m.first->stats().measurements;
    m.full = std::make_unique<slam::Pipeline>(o);
    m.full->run(*io::openDataSource(excerpt()));
    return m;
  }();
  return m;
}

struct Localized {
  std::vector<slam::LocalizedScan> scans;
  slam::LocalizerStats stats;
  std::vector<common::Pose2> smoothed;  // each scan's, by local SLAM's trajectory and the map's fixes
};

// `follow`: the localizer follows local SLAM's trajectory (Localizer::followLocalTrajectory), as
// `urbanslam localize` does unless --no-smoothing.
Localized localizeRest(const std::optional<common::Pose2>& initial, const std::string& log = excerpt(), size_t skip = maps().skip,
                       size_t max_scans = 100000, bool follow = false) {
  const slam::Pipeline& map = *maps().first;
  slam::Localizer localizer(map.map(), map.options(), slam::localizerOptions(map.options()));
  if (initial) localizer.setInitialPose(*initial);
  test::SkippingSource src(io::openDataSource(log), skip);
  slam::LocalTrajectory local(map.options());
  if (follow) localizer.followLocalTrajectory(&local);
  Localized out;
  io::Measurement m;
  while (out.scans.size() < max_scans && src.next(m)) {
    local.add(m);
    if (auto r = localizer.add(m)) out.scans.push_back(*r);
  }
  out.stats = localizer.stats();
  out.smoothed =
      slam::smoothLocalization(local, out.scans, map.options().local.covariance_scale, map.options().keyframes.min_translation_m);
  return out;
}

std::vector<io::StampedPose> tracked(const std::vector<slam::LocalizedScan>& scans) {
  std::vector<io::StampedPose> out;
  for (const auto& s : scans)
    if (s.state == slam::LocalizationState::Tracking) out.push_back({s.timestamp, s.pose});
  return out;
}

// The excerpt's relations whose two ends are both tracked (none across a lost stretch).
std::vector<evaluation::Relation> relationsWithin(const std::vector<io::StampedPose>& traj) {
  std::vector<evaluation::Relation> inside;
  common::Pose2 unused;
  for (const auto& r : evaluation::readRelations(test::repoPath("rawlogs/fr079-raw-excerpt.relations")))
    if (evaluation::interpolatePose(traj, r.t1, 0.5, unused) && evaluation::interpolatePose(traj, r.t2, 0.5, unused)) inside.push_back(r);
  return inside;
}

// The full run's pose at a scan time (both place every scan of the excerpt).
common::Pose2 reference(double t) {
  common::Pose2 p;
  EXPECT_TRUE(evaluation::interpolatePose(maps().full->scanTrajectory(), t, 1.0, p));
  return p;
}

double distance(const common::Pose2& a, const common::Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

double percentileOf(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

// Started where the map ended: the relations between the tracked scans are met as well as by the
// mapping run over the whole excerpt, and the poses are those of that run (whose frame is
// the map's: both start at the same first scan).
TEST(Localizer, TracksTheRestOfTheExcerptAsWellAsTheFullRunMapsIt) {
  const common::Pose2 start = maps().first->scanTrajectory().back().pose;
  const Localized loc = localizeRest(start);
  const auto traj = tracked(loc.scans);
  ASSERT_GT(traj.size(), 200u);

  const std::vector<evaluation::Relation> inside = relationsWithin(traj);
  ASSERT_GE(inside.size(), 40u);
  const auto localized = evaluation::relationMetrics(traj, inside, 0.0, 0.5);
  const auto mapped = evaluation::relationMetrics(maps().full->scanTrajectory(), inside, 0.0, 0.5);
  EXPECT_EQ(localized.used, inside.size());
  // Within 10 % of the mapping run (the localization goal). With a match's covariance taken alone
  // instead of fused with the prediction's, the rotations are 23 % worse (0.453° against 0.363°).
  EXPECT_LT(localized.abs_trans_m.mean, 1.1 * mapped.abs_trans_m.mean);
  EXPECT_LT(localized.abs_rot_deg.mean, 1.1 * mapped.abs_rot_deg.mean);
  // The smoothed trajectory, at the same scans.
  ASSERT_EQ(loc.smoothed.size(), loc.scans.size());
  std::vector<io::StampedPose> smoothed;
  for (size_t i = 0; i < loc.scans.size(); ++i)
    if (loc.scans[i].state == slam::LocalizationState::Tracking) smoothed.push_back({loc.scans[i].timestamp, loc.smoothed[i]});
  const auto smooth = evaluation::relationMetrics(smoothed, inside, 0.0, 0.5);
  // Measured: 0.026 m and 0.33° against the online poses' 0.028 m and 0.36° (the full run: 0.037 m,
  // 0.37°): local SLAM's motion between scans, where the online poses follow each map match.
  EXPECT_LT(smooth.abs_trans_m.mean, 0.95 * localized.abs_trans_m.mean);
  EXPECT_LT(smooth.abs_rot_deg.mean, 0.95 * localized.abs_rot_deg.mean);
  std::vector<double> smoothed_errors;
  for (const auto& p : smoothed) smoothed_errors.push_back(distance(p.pose, reference(p.timestamp)));
  EXPECT_LT(percentileOf(smoothed_errors, 0.5), 0.06);
  EXPECT_LT(percentileOf(smoothed_errors, 0.95), 0.2);

  std::vector<double> errors;
  for (const auto& p : traj) errors.push_back(distance(p.pose, reference(p.timestamp)));
  EXPECT_LT(percentileOf(errors, 0.5), 0.06);
  EXPECT_LT(percentileOf(errors, 0.95), 0.2);

  // The room the map never saw is not tracked, and the way back is found.
  EXPECT_GE(loc.stats.lost_events, 1u);
  EXPECT_GE(loc.stats.relocalisations, 1u);
  EXPECT_GT(loc.stats.lost_s, 30.0);
}

// Following local SLAM's trajectory, a confirmed pose is matched against the map once per
// keyframe spacing of travel: most scans are not matched, and the poses are as good.
TEST(Localizer, FollowingLocalSlamMatchesTheMapOncePerKeyframeSpacing) {
  const common::Pose2 start = maps().first->scanTrajectory().back().pose;
  const Localized loc = localizeRest(start, excerpt(), maps().skip, 100000, true);
  const auto traj = tracked(loc.scans);
  ASSERT_GT(traj.size(), 200u);
  const std::vector<evaluation::Relation> inside = relationsWithin(traj);
  ASSERT_GE(inside.size(), 40u);
  std::vector<io::StampedPose> smoothed;
  for (size_t i = 0; i < loc.scans.size(); ++i)
    if (loc.scans[i].state == slam::LocalizationState::Tracking) smoothed.push_back({loc.scans[i].timestamp, loc.smoothed[i]});
  const auto smooth = evaluation::relationMetrics(smoothed, inside, 0.0, 0.5);
  const auto mapped = evaluation::relationMetrics(maps().full->scanTrajectory(), inside, 0.0, 0.5);
  // Measured: smoothed 0.027 m / 0.33°, the full run 0.034 m / 0.37° on these relations; the
  // online poses 0.046 m / 0.64° (each map match corrects what local SLAM carried since the last,
  // 2.7 cm and 0.4° on average: the relations that span one take it whole).
  EXPECT_LT(smooth.abs_trans_m.mean, 1.1 * mapped.abs_trans_m.mean);
  EXPECT_LT(smooth.abs_rot_deg.mean, 1.1 * mapped.abs_rot_deg.mean);
  // Most scans are carried, not matched (216 of 304 tracked).
  EXPECT_GT(loc.stats.matches_skipped, loc.stats.tracking / 2);
  // Local SLAM's view never breaks off on an ordinary drive (a kidnapping's sign).
  EXPECT_EQ(loc.stats.discontinuities, 0u);
  std::vector<double> errors;
  for (const auto& p : traj) errors.push_back(distance(p.pose, reference(p.timestamp)));
  std::vector<double> smoothed_errors;
  for (const auto& p : smoothed) smoothed_errors.push_back(distance(p.pose, reference(p.timestamp)));
  // Measured: online 0.055 / 0.18 m, smoothed (below) as good or better.
  EXPECT_LT(percentileOf(errors, 0.5), 0.08);
  EXPECT_LT(percentileOf(errors, 0.95), 0.25);
  EXPECT_LT(percentileOf(smoothed_errors, 0.95), 0.2);
  // The room the map never saw is still noticed, and the way back found.
  EXPECT_GE(loc.stats.lost_events, 1u);
  EXPECT_GE(loc.stats.relocalisations, 1u);
}

// No initial pose: the place search finds the start at once, in the right place.
TEST(Localizer, FindsItsPlaceWithoutAnInitialPose) {
  const Localized loc = localizeRest(std::nullopt, excerpt(), maps().skip, 50);
  ASSERT_GE(loc.stats.first_fix_s, 0.0);
  EXPECT_LE(loc.stats.first_fix_s, 3.0);
  for (const auto& s : loc.scans) {
    if (s.state != slam::LocalizationState::Tracking) continue;
    EXPECT_LT(distance(s.pose, reference(s.timestamp)), 0.2) << s.timestamp;
    EXPECT_LT(std::abs(common::wrapToPi(s.pose.phi - reference(s.timestamp).phi)), 3 * M_PI / 180) << s.timestamp;
  }
}

// Kidnapped: told a pose 3 m and 40° off, it loses track and the place search puts it back.
// Also when following local SLAM: its tighter motion must not let matches confirm the wrong pose.
TEST(Localizer, RecoversFromAWrongInitialPose) {
  for (const bool follow : {false, true}) {
    SCOPED_TRACE(follow ? "following local SLAM" : "odometry only");
    const common::Pose2 truth = maps().first->scanTrajectory().back().pose;
    const Localized loc = localizeRest(common::compose(truth, {3.0, -1.5, 0.7}), excerpt(), maps().skip, 60, follow);
    size_t relocalised_at = loc.scans.size();
    for (size_t i = 0; i < loc.scans.size(); ++i)
      if (loc.scans[i].relocalised) {
        relocalised_at = i;
        break;
      }
    ASSERT_LT(relocalised_at, 30u);
    for (size_t i = relocalised_at; i < loc.scans.size(); ++i) {
      const auto& s = loc.scans[i];
      EXPECT_EQ(s.state, slam::LocalizationState::Tracking) << s.timestamp;
      EXPECT_LT(distance(s.pose, reference(s.timestamp)), 0.2) << s.timestamp;
    }
  }
}

namespace {

// The rest of the excerpt with the vehicle carried from its `from`-th scan to its `to`-th: the
// measurements up to the first, then those from the second on, their times moved back to follow
// on and their odometry composed to continue from where it was (the wheels felt nothing).
std::vector<io::Measurement> kidnapped(size_t from, size_t to, double* jump_time, double* time_shift) {
  std::vector<io::Measurement> all;
  test::SkippingSource src(io::openDataSource(excerpt()), maps().skip);
  io::Measurement m;
  while (src.next(m)) all.push_back(m);
  std::vector<size_t> scans;
  for (size_t i = 0; i < all.size(); ++i)
    if (std::holds_alternative<io::LaserScan>(all[i])) scans.push_back(i);
  const size_t cut = scans.at(from), resume = scans.at(to);
  common::Pose2 odom_cut, odom_resume;
  for (size_t i = 0; i < cut; ++i)
    if (const auto* o = std::get_if<io::OdometryReading>(&all[i])) odom_cut = o->pose;
  for (size_t i = resume; i < all.size(); ++i)
    if (const auto* o = std::get_if<io::OdometryReading>(&all[i])) {
      odom_resume = o->pose;
      break;
    }
  const common::Pose2 carried = common::compose(odom_cut, common::inverse(odom_resume));
  *jump_time = io::timestampOf(all[cut]);
  *time_shift = *jump_time - io::timestampOf(all[resume]);
  std::vector<io::Measurement> out(all.begin(), all.begin() + static_cast<long>(cut));
  for (size_t i = resume; i < all.size(); ++i) {
    io::Measurement x = all[i];
    if (auto* s = std::get_if<io::LaserScan>(&x)) {
      s->timestamp += *time_shift;
    } else if (auto* o = std::get_if<io::OdometryReading>(&x)) {
      o->timestamp += *time_shift;
      o->pose = common::compose(carried, o->pose);
    } else {
      continue;
    }
    out.push_back(x);
  }
  return out;
}

}  // namespace

// Carried elsewhere while tracked (scan 120 of the rest to scan 230, 3 m away and turned):
// local SLAM's view breaks off within a second, the pose loses its confirmation, and the place
// searches that follow the loss look at the whole map and find the vehicle. With the monitor
// alone, the dead reckoning from the old pose keeps every search away from the right place to
// the end of the excerpt. (Every search there is slow to win: FR079's corridors look alike from
// a single scan, as on the benchmark's own jumps, bench/localize/RESULTS.md.)
TEST(Localizer, KidnappedVehicleIsFoundWhereTheDeadReckoningCannotBe) {
  double jump_time = 0, shift = 0;
  const std::vector<io::Measurement> log = kidnapped(120, 230, &jump_time, &shift);
  ASSERT_GT(distance(reference(jump_time), reference(jump_time - shift)), 2.5);
  const slam::Pipeline& map = *maps().first;
  for (const bool detect : {true, false}) {
    SCOPED_TRACE(detect ? "local SLAM's discontinuity" : "the monitor alone");
    slam::LocalizerOptions o = slam::localizerOptions(map.options());
    if (!detect) o.discontinuity_scans = 1000000;
    slam::Localizer localizer(map.map(), map.options(), o);
    localizer.setInitialPose(map.scanTrajectory().back().pose);
    slam::LocalTrajectory local(map.options());
    localizer.followLocalTrajectory(&local);
    double found = -1, noticed = -1;  // log time from the jump
    for (const io::Measurement& m : log) {
      local.add(m);
      const auto r = localizer.add(m);
      if (!r) continue;
      if (noticed < 0 && localizer.stats().discontinuities > 0) noticed = r->timestamp - jump_time;
      if (r->timestamp < jump_time || found >= 0 || r->state != slam::LocalizationState::Tracking) continue;
      const common::Pose2 truth = reference(r->timestamp - shift);
      if (distance(r->pose, truth) < 0.3 && std::abs(common::wrapToPi(r->pose.phi - truth.phi)) < 5 * M_PI / 180)
        found = r->timestamp - jump_time;
    }
    if (detect) {
      EXPECT_GE(noticed, 0.0);
      EXPECT_LE(noticed, 1.5);
      EXPECT_GE(found, 0.0);  // measured: 41.8 s
    } else {
      EXPECT_LT(found, 0.0) << found;
    }
  }
}

// A building the map has never seen (the Intel lab): no place is ever accepted.
TEST(Localizer, StaysLostWhereTheMapHasNeverBeen) {
  const Localized loc = localizeRest(std::nullopt, test::repoPath("rawlogs/intel.rawlog"), 0, 120);
  ASSERT_EQ(loc.scans.size(), 120u);
  EXPECT_GT(loc.stats.place_searches, 10u);
  EXPECT_EQ(loc.stats.relocalisations, 0u);
  EXPECT_EQ(loc.stats.tracking, 0u);
  for (const auto& s : loc.scans) EXPECT_FALSE(s.has_pose);
}

namespace {

// The map with every keyframe copied `offset` away (a second wing that looks exactly like the
// first) and the keyframes within `radius` of `hole` taken out of one of the two (the original's
// frame; `hole_in_copy`: out of the copy), so that near the hole a scan fits one wing better.
std::unique_ptr<slam::Map> twinWings(const slam::Map& map, const common::Pose2& offset, const Eigen::Vector2d& hole, double radius,
                                     bool hole_in_copy = false) {
  auto out = std::make_unique<slam::Map>(nullptr, 1.0);
  size_t index = 0;
  for (const bool copy : {false, true})
    for (const slam::Keyframe& k : map.keyframes()) {
      if (copy == hole_in_copy && std::hypot(k.pose.x - hole.x(), k.pose.y - hole.y()) < radius) continue;
      slam::Keyframe kf = k;
      kf.index = index++;
      if (copy) kf.pose = common::compose(offset, k.pose);
      out->addKeyframe(kf, io::CompactScan(map.scan(k.index)));
    }
  return out;
}

}  // namespace

// Where the vehicle first loses track (the place search found it again there in the plain map),
// its own wing's keyframes are missing and the scan fits the other wing, 85 m away, at least as
// well: a place search over the whole map tracks it there for the rest of the log. The pose
// tracked up to there, carried on by the odometry, rules the other wing out (the search does not
// even look there): no scan is ever tracked in a wrong place.
TEST(Localizer, NeverTracksInALookAlikeWingFarFromWhereItWasLost) {
  const common::Pose2 start = maps().first->scanTrajectory().back().pose;
  // Where the vehicle came back in the plain map (the place the twin map makes ambiguous).
  const Localized plain = localizeRest(start);
  std::optional<common::Pose2> back;
  for (const auto& s : plain.scans)
    if (s.relocalised) {
      ASSERT_LT(distance(s.pose, reference(s.timestamp)), 0.2);
      back = s.pose;
      break;
    }
  ASSERT_TRUE(back);

  const slam::Pipeline& first = *maps().first;
  const auto twins = twinWings(first.map(), {80.0, 30.0, 0.5}, {back->x, back->y}, 6.0);
  slam::Localizer localizer(*twins, first.options(), slam::localizerOptions(first.options()));
  localizer.setInitialPose(start);
  test::SkippingSource src(io::openDataSource(excerpt()), maps().skip);
  io::Measurement m;
  size_t tracked_scans = 0;
  while (src.next(m))
    if (auto r = localizer.add(m); r && r->state == slam::LocalizationState::Tracking) {
      ++tracked_scans;
      EXPECT_LT(distance(r->pose, reference(r->timestamp)), 0.5) << r->timestamp;
    }
  EXPECT_GT(tracked_scans, 20u);
  EXPECT_GE(localizer.stats().lost_events, 1u);
}

namespace {

// The rest of the excerpt's scans as the localizer sees them (input filter applied), with the
// full run's pose at each.
struct RestScan {
  double timestamp;
  alignment::PointSet points;
  common::Pose2 truth;
};

std::vector<RestScan> restScans() {
  const slam::Pipeline& first = *maps().first;
  const slam::InputFilter input(first.options().input);
  const slam::LocalizerOptions o = slam::localizerOptions(first.options());
  test::SkippingSource src(io::openDataSource(excerpt()), maps().skip);
  std::vector<RestScan> out;
  io::Measurement m;
  while (src.next(m))
    if (auto* scan = std::get_if<io::LaserScan>(&m); scan && input.accepts(scan->label)) {
      input.limitRanges(*scan);
      out.push_back({scan->timestamp, alignment::pointSetFromScan(*scan, o.areas.scan_model, true), reference(scan->timestamp)});
    }
  return out;
}

}  // namespace

// A place and its copy that one scan cannot tell apart (the place search says ambiguous) are
// told apart by following both while the vehicle drives on (the full run's motion): the place
// where the vehicle really is wins once the walls the copy lacks come into view, at the full
// run's pose. Followed with the copy first (a search whose winner was the copy), the copy never
// wins: the following gives up.
TEST(PlaceHypotheses, FollowingTellsApartAPlaceAndItsCopyThatOneScanCannot) {
  const slam::Pipeline& first = *maps().first;
  const std::vector<RestScan> rest = restScans();
  const common::Pose2 offset{60.0, -40.0, 0.3};
  const slam::LocalizerOptions o = slam::localizerOptions(first.options());
  size_t followed = 0;
  for (size_t hole_at = 60; hole_at < rest.size() && followed < 3; hole_at += 40) {
    const Eigen::Vector2d hole(rest[hole_at].truth.x, rest[hole_at].truth.y);
    const auto map = twinWings(first.map(), offset, hole, 3.0, true);
    slam::MapAreas areas(*map, o.areas);
    slam::PlaceRecognizer places(*map, areas, o.places);
    const alignment::PriorMatcherOptions matcher = areas.options().matcher;
    // The first scan on the way to the hole that one scan cannot place, its two places the
    // original and the copy.
    for (size_t k = hole_at - 40; k + 5 < hole_at; k += 5) {
      const slam::PlaceHypothesis h = places.locate(rest[k].points, matcher);
      if (h.reason != "ambiguous" || h.places.size() > 4) continue;
      const common::Pose2 copy = common::compose(offset, rest[k].truth);
      const auto near = [&](const common::Pose2& c, const common::Pose2& p) { return distance(c, p) < 0.5; };
      const bool both = std::any_of(h.places.begin(), h.places.end(), [&](const auto& c) { return near(c, rest[k].truth); }) &&
                        std::any_of(h.places.begin(), h.places.end(), [&](const auto& c) { return near(c, copy); });
      if (!both) continue;
      for (const bool copy_first : {false, true}) {
        slam::PlaceHypotheses following(areas, o.places, o.following);
        const std::vector<common::Pose2> pair =
            copy_first ? std::vector<common::Pose2>{copy, rest[k].truth} : std::vector<common::Pose2>{rest[k].truth, copy};
        following.start(pair, places.searchPoints(rest[k].points), rest[k].timestamp);
        ASSERT_TRUE(following.active());
        slam::PlaceHypotheses::Outcome outcome = slam::PlaceHypotheses::Outcome::Following;
        size_t j = k + 1;
        for (; j < rest.size() && outcome == slam::PlaceHypotheses::Outcome::Following; ++j)
          outcome =
              following.update(common::between(rest[j - 1].truth, rest[j].truth), places.searchPoints(rest[j].points), rest[j].timestamp);
        if (copy_first) {
          EXPECT_NE(outcome, slam::PlaceHypotheses::Outcome::Decided) << "the copy won at " << rest[j - 1].timestamp;
        } else {
          ASSERT_EQ(outcome, slam::PlaceHypotheses::Outcome::Decided) << "from " << rest[k].timestamp;
          EXPECT_LT(distance(following.winner(), rest[j - 1].truth), 0.3) << rest[j - 1].timestamp;
          EXPECT_LT(std::abs(common::wrapToPi(following.winner().phi - rest[j - 1].truth.phi)), 3 * M_PI / 180);
        }
      }
      ++followed;
      break;
    }
  }
  EXPECT_GE(followed, 2u);
}
