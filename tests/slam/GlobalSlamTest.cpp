// Global SLAM's candidate schedule, through GlobalSlam itself: far from the map the pose-gated
// candidates are searched at every far_every_n_keyframes-th keyframe only, along a revisit at every
// revisit_every_n_keyframes-th, except while a closure hypothesis waits for its confirmation,
// which only the next keyframes' searches can bring.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "CameraAhead.h"
#include "CastScan.h"
#include "ConstantScan.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"

using namespace urbanslam;

namespace {

struct CandidateLog : slam::PipelineObserver {
  std::map<size_t, std::vector<size_t>> by_keyframe;  // the candidates of each search
  void onCandidates(const slam::CandidatesEvent& e) override { by_keyframe[e.keyframe] = *e.candidates; }
};

struct Run {
  slam::PipelineOptions options;
  slam::PipelineStats stats;
  CandidateLog log;
  std::vector<slam::PipelineObserver*> observers{&log};
  slam::Map map{std::make_unique<esdf::Esdf>(), 2.0};
  std::unique_ptr<slam::GlobalSlam> global;
};

// Keyframes 0-199 one metre apart along x, each odometry link 0.5 m uncertain; keyframe 200 back
// at x = 100 (5 m uncertain relative to keyframe 100: far from the map) and on from there.
// `late_range_m`: the range of the scans from keyframe 200 on (the earlier ones see 10 m);
// `last`: the last keyframe; [loop_closure] revisit_every_n_keyframes and max_candidates.
std::unique_ptr<Run> drive(double late_range_m, size_t last = 203, int revisit_every_n = 1, int max_candidates = 3) {
  auto r = std::make_unique<Run>();
  r->options.loop_closure.revisit_every_n_keyframes = revisit_every_n;
  r->options.loop_closure.max_candidates = max_candidates;
  r->options.loop_closure.detector = slam::LoopClosureOptions::Detector::None;
  r->options.loop_closure.appearance_min_sigma_m = 3;
  r->options.loop_closure.far_every_n_keyframes = 4;
  // Every scan is the same semicircle: path submaps of them align anywhere, and the submap check
  // would refuse every closure far from the map. The schedule is the subject here. A semicircle
  // that moves with the vehicle is what the keyframes before and after see through: every
  // return would be hidden as moving (MovingReturns.h).
  r->options.loop_closure.submap_check_path_m = 0;
  r->options.loop_closure.moving_returns_neighbours = 0;
  r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
  slam::KeyframeConstraint c;
  c.cov = Eigen::Vector3d(0.25, 0.25, 1e-6).asDiagonal();
  for (size_t k = 0; k <= last; ++k) {
    c.z = {k == 200 ? -99.0 : 1.0, 0, 0};  // from x = 199 back to 100, then on along x
    const float range = static_cast<float>(k < 200 ? 10.0 : late_range_m);
    r->global->addKeyframe({k, static_cast<double>(k), {}, true, false, {}}, io::CompactScan(test::constantScan(k, range, 80)), c);
    if (k >= 200) r->global->closeLoops(k, std::chrono::steady_clock::now());
  }
  return r;
}

// Global SLAM over keyframes 0..205 a metre apart along x, each step with this covariance.
void driveStraight(::Run& r, const Eigen::Matrix3d& step_cov) {
  r.global = std::make_unique<slam::GlobalSlam>(r.options, r.map, r.stats, r.observers);
  slam::KeyframeConstraint c;
  c.z = {1.0, 0, 0};
  c.cov = step_cov;
  for (size_t k = 0; k <= 205; ++k) r.global->addKeyframe({k, static_cast<double>(k), {}, false, true, {}}, io::CompactScan(), c);
}

}  // namespace

TEST(GlobalSlam, AClosureAwaitingConfirmationMakesTheNextKeyframesSearchFarFromTheMap) {
  // The same scans before and after: keyframe 200 (a 4th) aligns with its nearest keyframes and
  // waits for a confirmation; keyframe 201 searches too, confirms it, and the closure is in.
  const auto same = drive(10.0);
  const auto& seen = same->log.by_keyframe;
  ASSERT_TRUE(seen.count(200) && seen.count(201));
  EXPECT_FALSE(seen.at(200).empty());
  EXPECT_FALSE(seen.at(201).empty());
  EXPECT_GE(same->stats.closures_accepted, 2u);

  // Scans that cannot align: no hypothesis waits after keyframe 200, so keyframes 201-203 (not
  // 4ths) search no keyframe near the estimate. (This half also shows that the drive is far from
  // the map: near it every keyframe searches.)
  const auto other = drive(3.0);
  const auto& none = other->log.by_keyframe;
  ASSERT_TRUE(none.count(200));
  EXPECT_FALSE(none.at(200).empty());
  for (size_t k : {201, 202, 203}) EXPECT_TRUE(!none.count(k) || none.at(k).empty()) << k;
  EXPECT_EQ(other->stats.closures_accepted, 0u);
}

// Along a revisit the search waits for the n-th keyframe after the newest closure: a closure
// waits for its confirmation at the next keyframe, the two go in, and the next two keyframes
// (with n = 3) are not searched. Every keyframe of the revisit searches with n = 1, and with
// n = 3 while a hypothesis waits (three candidates a search: two are left waiting).
TEST(GlobalSlam, AlongARevisitTheSearchWaitsForTheNthKeyframeAfterTheNewestClosure) {
  const auto every = drive(10.0, 209, 1, 1);
  const auto strided = drive(10.0, 209, 3, 1);
  const auto waiting = drive(10.0, 209, 3, 3);
  const auto searched_from_200 = [](const ::Run& r) {
    std::vector<size_t> out;
    for (const auto& [k, candidates] : r.log.by_keyframe)
      if (k >= 200) out.push_back(k);
    return out;
  };
  const std::vector<size_t> searched = searched_from_200(*strided);
  EXPECT_EQ(searched, (std::vector<size_t>{200, 201, 204, 205, 208, 209}));
  EXPECT_EQ(searched_from_200(*every), (std::vector<size_t>{200, 201, 202, 203, 204, 205, 206, 207, 208, 209}));
  EXPECT_EQ(searched_from_200(*waiting), searched_from_200(*every));
  // Each search of the revisit closes the loop (a closure and its confirmation).
  std::vector<size_t> closed;
  for (const slam::LoopClosureRecord& c : strided->global->closures())
    if (c.accepted) closed.push_back(c.to);
  EXPECT_EQ(closed, searched);
  EXPECT_EQ(every->stats.closures_accepted, 10u);
}

// A camera closure's full pose goes in only where the estimate knows the pair within
// appearance_min_sigma_m (a copy of a facade design tens of metres along the street cannot then
// pass the gate with its length); beyond, its bearing and heading only.
TEST(GlobalSlam, AFullCameraPoseIsUsedOnlyWhereTheEstimateTellsAFacadeFromItsCopy) {
  ::Run r;
  r.options.loop_closure.confirm_window = 0;
  r.options.loop_closure.appearance_min_sigma_m = 3.0;
  driveStraight(r, Eigen::Vector3d(0.09, 0.09, 1e-6).asDiagonal());  // 0.3 m a step: 0.7 m over 5 steps, 4.2 m over 200
  const auto measured = [](double along_m) {
    slam::CameraMeasurement m;
    m.mount = common::Pose2{1.0, 0.0, M_PI / 2};  // looking left; the vehicle drives along x
    m.relative.valid = true;
    m.relative.bearing_rad = -M_PI / 2;  // camera b to the right of camera a's view: ahead along x
    m.relative.cov = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
    m.relative.depth_per_baseline = 0.01;
    m.metric.valid = true;
    m.metric.pose = common::Pose2{0.0, -along_m, 0.0};
    m.metric.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    return m;
  };
  r.global->proposeImageClosure(200, 205, 1.0, measured(5.0), std::chrono::steady_clock::now());
  r.global->proposeImageClosure(5, 205, 1.0, measured(200.0), std::chrono::steady_clock::now());
  const auto& closures = r.global->closures();
  ASSERT_EQ(closures.size(), 2u);
  EXPECT_TRUE(closures[0].accepted) << slam::reasonName(closures[0].reason);
  EXPECT_FALSE(closures[0].bearing_only);
  // The vehicle-frame measurement is the camera's pose carried through the mount: 5 m along x.
  EXPECT_NEAR(closures[0].measurement.x, 5.0, 1e-9);
  EXPECT_NEAR(closures[0].measurement.y, 0.0, 1e-9);
  EXPECT_TRUE(closures[1].bearing_only);
}

// A camera-only proposal whose images, at the distance the estimate puts between the cameras,
// would show a scene beyond max_scene_depth_m is refused before the gate (a copy of a facade 200
// m further along the street), and the same images between keyframes 5 m apart are not.
TEST(GlobalSlam, ACameraClosureWhoseSceneWouldLieBeyondTheCamerasReachIsRefused) {
  ::Run r;
  r.options.loop_closure.max_scene_depth_m = 150;
  r.options.loop_closure.confirm_window = 0;
  driveStraight(r, Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal());  // 1 cm per metre: 0.14 m after 200 m
  slam::CameraMeasurement m;
  m.mount = common::Pose2{1.0, 0.0, M_PI / 2};  // looking left; the vehicle drives along x
  m.relative.valid = true;
  m.relative.bearing_rad = -M_PI / 2;  // camera b to the right of camera a's view: ahead along x
  m.relative.heading_rad = 0;
  m.relative.cov = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  m.relative.depth_per_baseline = 2.0;                                                // a facade 10 m away seen from 5 m apart
  r.global->proposeImageClosure(5, 205, 1.0, m, std::chrono::steady_clock::now());    // 200 m: 400 m deep
  r.global->proposeImageClosure(200, 205, 1.0, m, std::chrono::steady_clock::now());  // 5 m: 10 m deep
  const auto& closures = r.global->closures();
  ASSERT_EQ(closures.size(), 2u);
  EXPECT_EQ(closures[0].reason, slam::ClosureReason::SceneDepth);
  EXPECT_FALSE(closures[0].accepted);
  EXPECT_NE(closures[1].reason, slam::ClosureReason::SceneDepth);
  EXPECT_TRUE(closures[1].accepted) << slam::reasonName(closures[1].reason);
}

// A closure the scans measured waits for a second closure to agree with it, unless the images
// nearest its keyframes measure the same full relative pose: then it goes in at once, confirmed
// by the camera. Images that measure another pose (a metre off) confirm nothing: the closure
// waits, and the next keyframe's closure confirms it as before. The drive of the first test: the
// scans of keyframes 200 and on are those of keyframes 100 and on, at the same places.
TEST(GlobalSlam, AClosureIsConfirmedByTheCameraWhenTheImagesMeasureTheSamePose) {
  const auto run = [](double camera_error_m, bool enabled) {
    auto r = std::make_unique<::Run>();
    r->options.loop_closure.detector = slam::LoopClosureOptions::Detector::None;
    r->options.loop_closure.submap_check_path_m = 0;
    r->options.loop_closure.moving_returns_neighbours = 0;  // as in drive(): the semicircle moves with the vehicle
    r->options.loop_closure.camera_confirmation = enabled;
    r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
    size_t asked = 0;
    // The images nearest keyframes a and b are those of a - 1 and b: camera b is one metre ahead
    // of camera a-1 (a and b at the same place, one scan seen twice). The camera looks left
    // (mount yaw 90°): ahead of the vehicle is -y in its frame, its x the vehicle's left.
    r->global->setCameraMeasurer([&asked, camera_error_m](size_t a, size_t b) {
      ++asked;
      slam::CameraPairView v;
      v.earlier = a - 1;
      v.current = b;
      v.camera.mount = common::Pose2{1.0, 0.5, M_PI / 2};
      v.camera.relative.valid = true;
      v.camera.metric.valid = true;
      v.camera.metric.pose = common::Pose2{camera_error_m, -1.0, 0.0};
      return std::optional<slam::CameraPairView>(v);
    });
    slam::KeyframeConstraint c;
    c.cov = Eigen::Vector3d(0.25, 0.25, 1e-6).asDiagonal();
    for (size_t k = 0; k <= 201; ++k) {
      c.z = {k == 200 ? -99.0 : 1.0, 0, 0};
      r->global->addKeyframe({k, static_cast<double>(k), {}, true, false, {}}, io::CompactScan(test::constantScan(k, 10.0, 80)), c);
      if (k >= 200) r->global->closeLoops(k, std::chrono::steady_clock::now());
    }
    return std::make_pair(std::move(r), asked);
  };
  const auto accepted_at = [](const ::Run& r, size_t keyframe, slam::Confirmation by) {
    const auto closures = r.global->closures();
    return std::count_if(closures.begin(), closures.end(),
                         [&](const slam::LoopClosureRecord& c) { return c.accepted && c.to == keyframe && c.confirmed_by == by; });
  };
  const auto [agree, asked_agree] = run(0.0, true);
  EXPECT_GE(asked_agree, 1u);
  EXPECT_EQ(accepted_at(*agree, 200, slam::Confirmation::Camera), 1);
  const auto [off, asked_off] = run(1.0, true);
  EXPECT_GE(asked_off, 1u);
  EXPECT_EQ(accepted_at(*off, 200, slam::Confirmation::Camera), 0);
  EXPECT_EQ(accepted_at(*off, 201, slam::Confirmation::Closure), 1);
  EXPECT_EQ(accepted_at(*off, 200, slam::Confirmation::Closure), 1);  // the waiting one, confirmed by 201's
  const auto [disabled, asked_disabled] = run(0.0, false);
  EXPECT_EQ(asked_disabled, 0u);
  EXPECT_EQ(accepted_at(*disabled, 200, slam::Confirmation::Camera), 0);
}

// A closure the camera itself measured (no scans) is not confirmed by the camera's view of the
// same pair: that would be one measurement agreeing with itself. It waits for a second closure.
TEST(GlobalSlam, ACameraClosureIsNotConfirmedByItsOwnImages) {
  ::Run r;
  r.options.loop_closure.appearance_min_sigma_m = 3.0;
  driveStraight(r, Eigen::Vector3d(0.09, 0.09, 1e-6).asDiagonal());
  slam::CameraMeasurement m;
  m.mount = common::Pose2{1.0, 0.0, M_PI / 2};  // looking left; the vehicle drives along x
  m.relative.valid = true;
  m.relative.bearing_rad = -M_PI / 2;  // camera b ahead along x
  m.relative.cov = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  m.relative.depth_per_baseline = 2.0;
  m.metric.valid = true;
  m.metric.pose = common::Pose2{0.0, -5.0, 0.0};  // 5 m ahead: the drive's truth
  m.metric.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
  size_t asked = 0;
  r.global->setCameraMeasurer([&](size_t a, size_t b) {
    ++asked;
    return std::optional<slam::CameraPairView>(slam::CameraPairView{a, b, m});
  });
  r.global->proposeImageClosure(200, 205, 1.0, m, std::chrono::steady_clock::now());
  EXPECT_EQ(asked, 0u);
  EXPECT_EQ(r.stats.closures_accepted, 0u);  // waiting for a second closure
  r.global->finish();
  ASSERT_EQ(r.global->closures().size(), 1u);
  EXPECT_EQ(r.global->closures()[0].reason, slam::ClosureReason::Unconfirmed);
}

// A closure that the gate refuses by less than two closures' quantile (6 dof) waits; the next keyframe's
// closure, refused alike and agreeing with it, passes the joint gate with it and both go in
// (confirmed "jointly"). Closures that disagree, or drift beyond the pair's quantile, stay refused.
// The camera measures each pair's full pose here (keyframes without scans): the measurement is
// what the test sets.
TEST(GlobalSlam, TwoClosuresJustBeyondTheGateGoInWhenTheyAgreeAndPassItJointly) {
  const auto run = [](double shift1_m, double shift2_m, bool joint_gate) {
    auto r = std::make_unique<::Run>();
    r->options.loop_closure.appearance_min_sigma_m = 3.0;
    r->options.loop_closure.joint_gate = joint_gate;
    driveStraight(*r, Eigen::Vector3d(0.09, 0.09, 1e-6).asDiagonal());
    // Keyframes 150 -> 200 and 151 -> 201: 50 m along x, 2.1 m uncertain (sigma); each measured
    // `shift` metres longer.
    for (const auto& [earlier, shift] : {std::make_pair(size_t{150}, shift1_m), std::make_pair(size_t{151}, shift2_m)})
      r->global->proposeImageClosure(earlier, earlier + 50, 1.0, test::cameraAhead(50.0 + shift), std::chrono::steady_clock::now());
    r->global->finish();
    return r->global->closures();
  };
  const auto count = [](const std::vector<slam::LoopClosureRecord>& closures, bool accepted, slam::ClosureReason reason) {
    return std::count_if(closures.begin(), closures.end(),
                         [&](const slam::LoopClosureRecord& c) { return c.accepted == accepted && c.reason == reason; });
  };
  // The filter's gate (esdf::EsdfOptions, 0.999): 16.27 for one closure, 22.46 for two. sigma^2
  // = 50 x 0.09 m^2: a shift of 9.25 m is d^2 19.0.
  const auto agree = run(9.25, 9.25, true);
  ASSERT_EQ(agree.size(), 2u);
  for (const auto& c : agree) {
    EXPECT_TRUE(c.accepted);
    EXPECT_EQ(c.confirmed_by, slam::Confirmation::Jointly);
    EXPECT_GT(c.mahalanobis2, 16.27);
    EXPECT_LE(c.mahalanobis2, c.gate_threshold);
  }
  EXPECT_EQ(count(run(9.25, 9.25, false), false, slam::ClosureReason::Gating), 2);  // without the joint gate
  EXPECT_EQ(count(run(9.25, -9.25, true), false, slam::ClosureReason::Gating), 2);  // they disagree
  EXPECT_EQ(count(run(11.0, 11.0, true), false, slam::ClosureReason::Gating), 2);   // d^2 27: beyond the pair's quantile too
}

// Keyframes 0..205 with each step 1 m uncertain (sigma): keyframe 200 is 7 m uncertain relative
// to keyframe 150, as a merged session hanging loosely from a map. Two agreeing closures from 150
// and 151 measure it `measured_m` ahead; the join check refuses any that is not within 1 m of
// 50 m. Returns the closures, and keyframe 200's estimate relative to 150 along x at the end.
std::pair<std::vector<slam::LoopClosureRecord>, double> closuresWithJoinCheck(double measured_m, bool check, int confirm_window) {
  ::Run r;
  r.options.loop_closure.appearance_min_sigma_m = 100;  // the camera's full pose is taken however uncertain the estimate
  r.options.loop_closure.confirm_window = confirm_window;
  driveStraight(r, Eigen::Vector3d(1.0, 1.0, 1e-6).asDiagonal());
  if (check) r.global->setJoinCheck([](const slam::LoopClosureRecord& c) { return std::abs(c.measurement.x - 50.0) > 1.0; });
  for (size_t earlier : {size_t{150}, size_t{151}})
    r.global->proposeImageClosure(earlier, earlier + 50, 1.0, test::cameraAhead(measured_m), std::chrono::steady_clock::now());
  r.global->finish();
  return {r.global->closures(), r.map.nodes()->mean(200)(0) - r.map.nodes()->mean(150)(0)};
}

TEST(GlobalSlam, RefusesTheClosuresTheJoinCheckSaysContradictTheJoin) {
  // 10 m off: inside the filter's gate (d^2 = 100 / 50 = 2), so without the check the look-alike
  // place goes in.
  const auto unchecked = closuresWithJoinCheck(60.0, false, 3).first;
  EXPECT_TRUE(std::any_of(unchecked.begin(), unchecked.end(), [](const slam::LoopClosureRecord& c) { return c.accepted; }));
  const auto refused = closuresWithJoinCheck(60.0, true, 3).first;
  ASSERT_EQ(refused.size(), 2u);
  for (const auto& c : refused) {
    EXPECT_FALSE(c.accepted);
    EXPECT_EQ(c.reason, slam::ClosureReason::Join);
    EXPECT_STREQ(slam::reasonName(c.reason), "join");
  }
  const auto agreeing = closuresWithJoinCheck(50.3, true, 3).first;
  ASSERT_EQ(agreeing.size(), 2u);
  for (const auto& c : agreeing) EXPECT_TRUE(c.accepted);
  // Without confirmation the loop closer would add a closure to the filter itself: under a join
  // check it leaves that to the check. Refused, the filter keeps its 50 m; agreeing, it goes in.
  const auto [at_once_refused, refused_m] = closuresWithJoinCheck(60.0, true, 0);
  for (const auto& c : at_once_refused) EXPECT_EQ(c.reason, slam::ClosureReason::Join);
  EXPECT_NEAR(refused_m, 50.0, 1e-6);
  const auto [at_once_agreeing, agreeing_m] = closuresWithJoinCheck(50.3, true, 0);
  EXPECT_TRUE(std::all_of(at_once_agreeing.begin(), at_once_agreeing.end(), [](const slam::LoopClosureRecord& c) { return c.accepted; }));
  EXPECT_NEAR(agreeing_m, 50.3, 0.05);
}

TEST(GlobalSlam, AHypothesisWithNoRoomToWaitForItsConfirmationIsOnRecordAsUnconfirmed) {
  // Five camera closures of keyframe 205, each within the gate, none confirming another (they
  // name one keyframe, and a confirmation comes from a later one): four may wait (4 x
  // confirm_window), the fifth has no room. Every one is on record, unconfirmed, by the end.
  auto r = std::make_unique<::Run>();
  r->options.loop_closure.confirm_window = 1;
  driveStraight(*r, Eigen::Vector3d(0.09, 0.09, 1e-6).asDiagonal());
  for (const double shift_m : {0.0, 1.0, -1.0, 2.0, -2.0}) {
    r->global->proposeImageClosure(155, 205, 1.0, test::cameraAhead(50.0 + shift_m), std::chrono::steady_clock::now());
  }
  r->global->finish();
  const std::vector<slam::LoopClosureRecord> closures = r->global->closures();
  ASSERT_EQ(closures.size(), 5u);
  for (const auto& c : closures) {
    EXPECT_FALSE(c.accepted);
    EXPECT_EQ(c.reason, slam::ClosureReason::Unconfirmed);
  }
  EXPECT_EQ(r->stats.closures_rejected, 5u);
}

TEST(GlobalSlam, AClosureTheRecentWindowCannotTakeUpBringsTheWholeMapsRecoveryBeforeTheNext) {
  // A straight drive whose odometry reads 1 m for every 1.005 m driven, each step 5 cm
  // uncertain: 5 m short after a kilometre. Keyframe 1000 closes on keyframe 0 (10 cm): within
  // the gate (d^2 about 10). The ten newest poses alone cannot take up 5 m against the closure,
  // so without the whole map's recovery the mean still misses it by about 1.4 m while its
  // covariance has shrunk to the closure's, and the next closure of the same loop (1001 on 1) is
  // refused with d^2 about 80.
  const double truth_step_m = 1.005;
  auto r = std::make_unique<::Run>();
  r->options.estimator.recent_window = 10;
  r->options.estimator.full_recovery_min_growth = 1000;  // none for the map's growth after the first
  r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
  slam::KeyframeConstraint c;
  c.z = {1.0, 0, 0};
  c.cov = Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 1e-8).asDiagonal();
  const Eigen::Matrix3d closure_info = Eigen::Vector3d(100, 100, 1e6).asDiagonal();
  const auto close = [&](size_t earlier, size_t current) {
    const double along = truth_step_m * static_cast<double>(current - earlier);
    r->global->addPlaceFix(earlier, current, common::Pose2{along, 0, 0}, closure_info, 1.0, slam::Proposer::Place);
  };
  for (size_t k = 0; k <= 1001; ++k) {
    r->global->addKeyframe({k, static_cast<double>(k), {}, false, false, {}}, io::CompactScan(), c);
    if (k == 10) close(0, 10);  // the map's first full recovery
    if (k == 1000) close(0, 1000);
    if (k == 1001) close(1, 1001);
  }
  const std::vector<slam::LoopClosureRecord> closures = r->global->closures();
  ASSERT_EQ(closures.size(), 3u);
  for (const auto& cl : closures) {
    EXPECT_TRUE(cl.accepted) << cl.from << " -> " << cl.to << ": d^2 " << cl.mahalanobis2;
    EXPECT_LT(cl.mahalanobis2, 16.27);  // the filter's gate (esdf::EsdfOptions, 0.999)
  }
  // The estimate where the drive truly is, before the run's last recovery.
  EXPECT_NEAR(r->map.keyframes()[1001].pose.x, truth_step_m * 1001, 0.1);
  EXPECT_NEAR(r->map.keyframes()[500].pose.x, truth_step_m * 500, 0.1);
}

namespace {

// The optimum of the map's edges, with pose 0 held at the origin: dense Gauss-Newton with
// central-difference Jacobians of e = ⊖z ⊕ (⊖x_a ⊕ x_b) (the heading wrapped), independent of
// the filter's information form, its sparse factorisation and its analytic Jacobians.
std::vector<Eigen::Vector3d> denseOptimum(const std::vector<slam::GraphEdge>& edges, std::vector<Eigen::Vector3d> x) {
  const auto error = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const common::Pose2& z) {
    const common::Pose2 r = common::between(common::Pose2{a.x(), a.y(), a.z()}, common::Pose2{b.x(), b.y(), b.z()});
    const common::Pose2 e = common::between(z, r);
    return Eigen::Vector3d(e.x, e.y, std::remainder(b.z() - a.z() - z.phi, 2 * M_PI));
  };
  const int n = static_cast<int>(x.size());
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * n);
    h.topLeftCorner<3, 3>() += 1e12 * Eigen::Matrix3d::Identity();  // pose 0 held
    g.head<3>() += 1e12 * x[0];
    for (const slam::GraphEdge& e : edges) {
      const int ia = static_cast<int>(e.from), ib = static_cast<int>(e.to);
      const Eigen::Vector3d e0 = error(x[ia], x[ib], e.measurement);
      Eigen::Matrix<double, 3, 6> j;
      for (int c = 0; c < 6; ++c) {
        const double d = 1e-6;
        Eigen::Vector3d a = x[ia], b = x[ib];
        (c < 3 ? a : b)(c % 3) += d;
        const Eigen::Vector3d plus = error(a, b, e.measurement);
        (c < 3 ? a : b)(c % 3) -= 2 * d;
        j.col(c) = (plus - error(a, b, e.measurement)) / (2 * d);
      }
      const Eigen::Matrix<double, 6, 6> jtj = j.transpose() * e.information * j;
      const Eigen::Matrix<double, 6, 1> jte = j.transpose() * e.information * e0;
      const int at[2] = {3 * ia, 3 * ib};
      for (int u = 0; u < 2; ++u) {
        g.segment<3>(at[u]) += jte.segment<3>(3 * u);
        for (int v = 0; v < 2; ++v) h.block<3, 3>(at[u], at[v]) += jtj.block<3, 3>(3 * u, 3 * v);
      }
    }
    const Eigen::VectorXd step = h.ldlt().solve(-g);
    for (int p = 0; p < n; ++p) x[static_cast<size_t>(p)] += step.segment<3>(3 * p);
    if (step.norm() < 1e-12) break;
  }
  return x;
}

}  // namespace

// A full recovery after a closure takes [estimator] full_recovery_steps Gauss-Newton steps; the
// run's last one goes on until nothing moves, even when nothing came after the closure's own
// recovery. A lap of a 20 m square, the odometry 1 cm and 0.3° short of the truth at every metre
// (24° of heading by the lap's end), closed at its end at the true relative pose: with one step
// or three, the poses after finish() are the optimum of the map's edges.
TEST(GlobalSlam, TheLastRecoveryReachesTheOptimumWhateverTheStepsBefore) {
  const auto truth = [](size_t k) {
    const double s = static_cast<double>(k % 80);  // metres along the square
    const int side = static_cast<int>(s / 20);
    const double along = s - 20 * side;
    const double corner[4][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}};
    const double heading = side * M_PI / 2;
    return common::Pose2{corner[side][0] + along * std::cos(heading), corner[side][1] + along * std::sin(heading), heading};
  };
  const auto run = [&](int steps) {
    auto r = std::make_unique<::Run>();
    r->options.estimator.full_recovery_min_growth = 0;  // a full recovery after every closure
    r->options.estimator.full_recovery_steps = steps;
    r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
    slam::KeyframeConstraint c;
    c.cov = Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.02 * 0.02).asDiagonal();
    const Eigen::Matrix3d tight = Eigen::Vector3d(1e4, 1e4, 1e5).asDiagonal();
    for (size_t k = 0; k <= 80; ++k) {
      if (k > 0) {
        const common::Pose2 step = common::between(truth(k - 1), truth(k));
        c.z = {step.x - 0.01, step.y, step.phi - 0.3 * M_PI / 180};
      }
      r->global->addKeyframe({k, static_cast<double>(k), {}, false, false, {}}, io::CompactScan(), c);
      if (k == 80) r->global->addPlaceFix(0, k, common::Pose2{}, tight, 1.0, slam::Proposer::Place);
    }
    // The closure's recovery leaves the factor of the current information (what its steps moved
    // is relinearised when the next recovery starts): the next exact covariance, the innovation
    // gate's, is column solves of that factor, not another factorisation of the map.
    esdf::Esdf& filter = *r->map.filter();
    const long long factorisations = filter.factorisations();
    filter.jointCovariance(40, 80, esdf::CovarianceMode::Exact);
    EXPECT_EQ(filter.factorisations(), factorisations) << steps << " steps";
    r->global->finish();
    return r;
  };
  const auto one = run(1), three = run(3);
  for (const auto* r : {one.get(), three.get()}) {
    EXPECT_EQ(r->stats.closures_accepted, 1u);
    std::vector<Eigen::Vector3d> start;
    for (const auto& k : r->map.keyframes()) start.emplace_back(k.pose.x, k.pose.y, k.pose.phi);
    const std::vector<Eigen::Vector3d> optimum = denseOptimum(r->map.edges().toVector(), start);
    double worst_m = 0, worst_rad = 0;
    for (size_t k = 0; k < start.size(); ++k) {
      worst_m = std::max(worst_m, (start[k].head<2>() - optimum[k].head<2>()).norm());
      worst_rad = std::max(worst_rad, std::fabs(std::remainder(start[k].z() - optimum[k].z(), 2 * M_PI)));
    }
    // 6e-8 m and 3e-9 rad here, with one step or three.
    EXPECT_LT(worst_m, 1e-6);
    EXPECT_LT(worst_rad, 1e-7);
  }
}

// A full recovery after a closure waits until the keyframes since the previous one have paid for
// its work at [estimator] full_recovery_work_per_keyframe each (the whole map's factorisation and
// sparse inverse, counted on the factor the previous one left): on a map whose factor fills
// faster than it grows, its cost per keyframe stays bounded. A straight drive closed every ten
// keyframes on the keyframe twenty back (the true relative pose); with no growth rule each
// closure would bring one.
TEST(GlobalSlam, AFullRecoveryWaitsUntilTheKeyframesSinceThePreviousHavePaidForIt) {
  struct Recoveries : slam::PipelineObserver {
    slam::Map* map = nullptr;
    std::vector<std::pair<size_t, double>> at;  // keyframes and the recovery's factor's work
    void onPosesUpdated(const slam::PosesUpdatedEvent& e) override {
      if (e.keyframe != static_cast<size_t>(-1)) at.emplace_back(map->size(), map->filter()->recoveryWork());
    }
  };
  const auto run = [](double work_per_keyframe) {
    auto r = std::make_unique<::Run>();
    Recoveries rec;
    rec.map = &r->map;
    r->observers.push_back(&rec);
    r->options.estimator.full_recovery_min_growth = 0;
    r->options.estimator.full_recovery_work_per_keyframe = work_per_keyframe;
    r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
    slam::KeyframeConstraint c;
    c.z = {1.0, 0, 0};
    c.cov = Eigen::Vector3d(0.01, 0.01, 1e-6).asDiagonal();
    const Eigen::Matrix3d closure_info = Eigen::Vector3d(1e4, 1e4, 1e6).asDiagonal();
    for (size_t k = 0; k < 400; ++k) {
      r->global->addKeyframe({k, static_cast<double>(k), {}, false, false, {}}, io::CompactScan(), c);
      if (k >= 30 && k % 10 == 0) r->global->addPlaceFix(k - 20, k, common::Pose2{20, 0, 0}, closure_info, 1.0, slam::Proposer::Place);
    }
    EXPECT_EQ(r->stats.closures_accepted, 37u);
    return rec.at;
  };
  const auto every = run(0);
  EXPECT_EQ(every.size(), 37u);  // after every closure
  ASSERT_GE(every.size(), 2u);
  // A budget at which the map's work needs about 40 keyframes by the end of the drive.
  const double budget = every.back().second / 40;
  const auto paid = run(budget);
  ASSERT_GE(paid.size(), 3u);
  EXPECT_LT(paid.size(), every.size());
  for (size_t i = 1; i < paid.size(); ++i) {
    const double since = static_cast<double>(paid[i].first - paid[i - 1].first);
    EXPECT_GE(since * budget, paid[i - 1].second) << "recovery " << i << " at " << paid[i].first;
    EXPECT_LT(since * budget, paid[i - 1].second + 10 * budget)
        << "recovery " << i << " came later than the next closure after it was paid";
  }
}

// A place search recognises a place to within its grid's reach: in a corridor it can settle a
// metre along it. The two keyframes' scans, aligned from the fix, measure the closure: a fix
// 0.8 m off along the room's length and held to 2 cm goes in where the scans put the keyframe.
TEST(GlobalSlam, APlaceFixIsMeasuredByItsKeyframesScansAlignedFromIt) {
  // A room 12 m x 6 m with two pillars, seen from its middle; keyframe 1 comes back near
  // keyframe 0 after a loose odometry link (1 m uncertain), as a merged session's keyframe does.
  std::vector<test::Segment> world;
  test::addBox(world, 0, 0, 12, 6, false);
  test::addBox(world, 3, 1, 3.6, 1.6, false);
  test::addBox(world, 8, 4, 8.8, 4.5, false);
  const common::Pose2 first{2, 3, 0.1}, second{2.4, 2.8, -0.15};
  std::mt19937 rng(7);
  auto r = std::make_unique<::Run>();
  r->options.loop_closure.moving_returns_neighbours = 0;
  r->global = std::make_unique<slam::GlobalSlam>(r->options, r->map, r->stats, r->observers);
  slam::KeyframeConstraint c;
  r->global->addKeyframe({0, 0.0, {}, true, false, {}}, io::CompactScan(test::castScan(first, world, 0.0, 30, rng)), c);
  c.z = common::Pose2{0, 0, 0};
  c.cov = Eigen::Vector3d(1.0, 1.0, 0.1).asDiagonal();
  r->global->addKeyframe({1, 1.0, {}, true, false, {}}, io::CompactScan(test::castScan(second, world, 0.0, 30, rng)), c);

  const common::Pose2 truth = common::between(first, second);
  const common::Pose2 off = common::compose(truth, common::Pose2{0.8, 0, 0});
  const Eigen::Matrix3d tight = Eigen::Vector3d(1 / 4e-4, 1 / 4e-4, 1 / 3e-6).asDiagonal();
  r->global->addPlaceFix(0, 1, off, tight, 1.0, slam::Proposer::Place);
  const std::vector<slam::LoopClosureRecord> closures = r->global->closures();
  ASSERT_EQ(closures.size(), 1u);
  ASSERT_TRUE(closures[0].accepted) << slam::reasonName(closures[0].reason);
  EXPECT_NEAR(closures[0].measurement.x, truth.x, 0.05);
  EXPECT_NEAR(closures[0].measurement.y, truth.y, 0.05);
  EXPECT_NEAR(closures[0].measurement.phi, truth.phi, 0.01);
  r->global->finish();
  const common::Pose2 placed = common::between(r->map.keyframes()[0].pose, r->map.keyframes()[1].pose);
  EXPECT_NEAR(placed.x, truth.x, 0.05);
  EXPECT_NEAR(placed.y, truth.y, 0.05);
}
