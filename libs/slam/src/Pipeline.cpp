#include "urbanslam/slam/Pipeline.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::slam {

namespace {
constexpr size_t kNone = std::numeric_limits<size_t>::max();
constexpr double kDeg = M_PI / 180.0;
}  // namespace

Pipeline::Pipeline(PipelineOptions options)
    : options_(std::move(options)),
      motion_(options_.motion, options_.vehicle),
      images_(options_.loop_closure.image_max_offset_s),
      submap_(options_.local),
      closer_(options_.loop_closure) {
  std::stringstream ss(options_.input.laser_labels);
  std::string label;
  while (std::getline(ss, label, ',')) {
    label.erase(0, label.find_first_not_of(" \t"));
    label.erase(label.find_last_not_of(" \t") + 1);
    if (!label.empty()) labels_.push_back(label);
  }
  esdf::EsdfOptions eo;
  eo.relinearise = options_.estimator.relinearise;
  eo.chi2_gate_probability = options_.loop_closure.chi2_gate_probability;
  eo.gate_covariance = esdf::CovarianceMode::Exact;
  esdf_ = std::make_unique<esdf::Esdf>(eo);
  if (options_.loop_closure.enabled && options_.loop_closure.detector == "laser") {
    // The AdaBoost classifier screens candidates before the (costlier) alignment. Its score is
    // the margin above the model's decision factor (eq. 3.30), so laser_threshold = 0 is the
    // model's own operating point.
    const std::string model = options_.loop_closure.laser_model.empty() ? laser_loop::kDefaultModelPath : options_.loop_closure.laser_model;
    laser_detector_ = std::make_unique<laser_loop::LoopDetector>(laser_loop::LoopDetector::fromFile(model));
    closer_.setScorer(
        [this](size_t earlier, size_t current) {
          return laser_detector_->score(laser_detector_->keyframe(current), earlier) - laser_detector_->factor();
        },
        "laser");
  }
}

Pipeline::~Pipeline() = default;

void PipelineStats::recordStep(double ms, size_t keyframes) {
  step_ms.push_back(ms);
  size_t decade = 0;
  for (size_t n = keyframes; n >= 10; n /= 10) ++decade;
  if (step_ms_by_decade.size() <= decade) step_ms_by_decade.resize(decade + 1);
  step_ms_by_decade[decade].push_back(ms);
}

void Pipeline::addObserver(PipelineObserver* observer) { observers_.push_back(observer); }

void Pipeline::setCandidateScorer(CandidateScorer scorer, std::string name) { closer_.setScorer(std::move(scorer), std::move(name)); }

bool Pipeline::acceptLabel(const std::string& label) const {
  if (labels_.empty()) return true;
  for (const auto& l : labels_)
    if (l == label) return true;
  return false;
}

void Pipeline::applyRangeLimits(io::LaserScan& scan) const {
  const double lo = options_.input.min_range_m, hi = options_.input.max_range_m;
  if (lo <= 0 && hi <= 0) return;
  for (size_t i = 0; i < scan.ranges.size(); ++i)
    if (scan.ranges[i] < lo || (hi > 0 && scan.ranges[i] >= hi)) scan.valid[i] = 0;
}

bool Pipeline::step(io::DataSource& source) {
  // Processing time (reading included) accumulates here, so a paused GUI run reports the same
  // real-time factor as a batch run.
  common::Stopwatch sw;
  const bool more = stepOnce(source);
  stats_.wall_s += sw.seconds();
  return more;
}

bool Pipeline::stepOnce(io::DataSource& source) {
  io::Measurement m;
  if (!source.next(m)) return false;
  ++stats_.measurements;
  const double t = io::timestampOf(m);
  if (!have_first_ts_) {
    stats_.first_timestamp = t;
    have_first_ts_ = true;
  }
  stats_.last_timestamp = t;
  const size_t last_anchor = anchors_.empty() ? kNone : anchors_.size() - 1;
  if (auto* scan = std::get_if<io::LaserScan>(&m)) {
    ++stats_.scans;
    onScan(std::move(*scan), source.progress());
  } else if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
    ++stats_.odometry;
    if (options_.motion.model != "steering") {
      motion_.addOdometry(*od);
      odometry_.push_back({od->timestamp, motion_.odometryPose(), last_anchor});
    }
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    ++stats_.drive;
    if (options_.motion.model != "odometry") {
      motion_.addDrive(*dr);
      odometry_.push_back({dr->timestamp, motion_.odometryPose(), last_anchor});
    }
  } else if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
    ++stats_.reference;
    reference_.push_back({ref->timestamp, ref->pose});
  } else if (const auto* img = std::get_if<io::CameraImage>(&m)) {
    ++stats_.images;
    for (auto* o : observers_) o->onImage(*img);
    onCameraImage(*img, source.progress());
  } else if (std::holds_alternative<io::GpsFix>(m)) {
    ++stats_.gps;
  }
  return true;
}

void Pipeline::run(io::DataSource& source) {
  while (step(source)) {
  }
  finish();
}

void Pipeline::finish() {
  if (auto last = images_.finish()) attachImage(*last);  // the last keyframe's image is final now
  for (LoopClosureRecord r : pending_) {  // hypotheses still waiting for a confirmation
    r.reason = "unconfirmed";
    r.accepted = false;
    reportClosure(r);
  }
  pending_.clear();
  if (dirty_since_recovery_) {
    common::Stopwatch sw;
    recoverAll();
    stats_.wall_s += sw.seconds();
  }
  stats_.keyframes = keyframes_.size();
  for (auto* o : observers_) o->onFinished();
}

common::Pose2 Pipeline::currentPose() const {
  if (keyframes_.empty()) return motion_.increment();
  return common::compose(keyframes_.back().pose, motion_.increment());
}

void Pipeline::onScan(io::LaserScan scan, double progress) {
  common::Stopwatch sw;
  if (!acceptLabel(scan.label)) return;
  ++stats_.scans_used;
  applyRangeLimits(scan);
  // Keyframe decision: has the vehicle moved or turned enough since the last keyframe?
  const common::Pose2& d = motion_.increment();
  // (The first scan after camera-only keyframes starts the laser map.)
  const bool make_keyframe = keyframes_.empty() || !have_scan_keyframe_ || std::hypot(d.x, d.y) >= options_.keyframes.min_translation_m ||
                             std::abs(d.phi) >= options_.keyframes.min_rotation_deg * kDeg;
  if (make_keyframe) {
    common::Stopwatch kw;
    addKeyframe(std::move(scan));
    stats_.keyframe_ms.push_back(kw.milliseconds());
  } else if (options_.local.scan_matching && options_.local.match_every_scan && !scan.ranges.empty() && keyframes_.back().hasScan() &&
             (anchors_.empty() || std::abs(scan.timestamp - anchors_.back().timestamp) >= options_.local.match_min_interval_s)) {
    anchorScan(scan);
  }
  const double ms = sw.milliseconds();
  stats_.recordStep(ms, keyframes_.size());
  StepEvent ev{stats_.scans_used, keyframes_.size(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

void Pipeline::addKeyframe(io::LaserScan scan) {
  const size_t k = keyframes_.size();
  const bool filter = options_.estimator.type == "esdf";
  // 1. Motion since the previous keyframe (odometry or steering model) and its covariance.
  common::Pose2 z = motion_.increment();
  Eigen::Matrix3d cov = motion_.covariance();
  cov.diagonal() += Eigen::Vector3d(1e-8, 1e-8, 1e-10);  // no motion at all is still a valid constraint
  // The previous keyframe's image is final once this keyframe exists (it may be nearer in time).
  if (auto done = images_.keyframeAdded(k, scan.timestamp)) attachImage(*done);
  Keyframe kf{k, scan.timestamp, {}, std::move(scan), false, {}};
  // Scan matching needs scans on both sides (camera-only keyframes have none).
  const bool match_scans = options_.local.scan_matching && kf.hasScan() && k > 0 && keyframes_.back().hasScan();
  if (k == 0) {
    // 2. The first keyframe anchors the map at the origin.
    if (filter) esdf_->initialise(esdf::Vec3::Zero(), esdf::Mat3::Identity() * 1e-9);
  } else {
    // 3. Local SLAM: refine the increment by aligning with the previous keyframe's scan.
    if (match_scans) localScanMatching(kf.scan, z, cov);
    const Eigen::Matrix3d info = cov.inverse();
    edges_.push_back({k - 1, k, z, info, false});
    if (filter) {
      // 4. ESDF prediction with augmentation: the keyframe becomes a delayed pose, O(1).
      esdf_->augmentRelative(static_cast<int>(k - 1), esdf::toVec(z), info);
      // 5. Recover the recent poses (bounded window, constant time between closures).
      esdf_->recoverRecent(std::max(0, static_cast<int>(k) - options_.estimator.recent_window));
      dirty_since_recovery_ = true;
    }
  }
  kf.pose = filter ? esdf::toPose(esdf_->mean(static_cast<int>(k)))
                   : (k == 0 ? common::Pose2{} : common::compose(keyframes_.back().pose, z));
  if (filter && k > 0) {
    // Window recovery moved the last `recent_window` keyframes too.
    for (size_t i = k > static_cast<size_t>(options_.estimator.recent_window) ? k - options_.estimator.recent_window : 0; i < k; ++i)
      keyframes_[i].pose = esdf::toPose(esdf_->mean(static_cast<int>(i)));
  }
  // The keyframe is an anchor of the trajectory at odometry times (offset identity).
  addAnchor({kf.timestamp, k, common::Pose2{}, motion_.odometryPose()});
  if (options_.local.scan_matching) submap_.addKeyframe(kf.scan);
  if (laser_detector_) laser_detector_->addKeyframe(kf.scan);  // features once per keyframe
  have_scan_keyframe_ = have_scan_keyframe_ || kf.hasScan();
  keyframes_.push_back(std::move(kf));
  motion_.reset();
  const Keyframe& added = keyframes_.back();
  closer_.addToIndex(added);
  std::array<double, 9> c{};
  if (filter && k > 0) {
    const esdf::Mat3 m = esdf_->marginalCovariance(static_cast<int>(k), esdf::CovarianceMode::Conservative);
    for (int i = 0; i < 9; ++i) c[static_cast<size_t>(i)] = m(i / 3, i % 3);
  }
  for (auto* o : observers_) o->onKeyframe({added.index, added.timestamp, added.pose, c, &added.scan});
  // 6-10. Global SLAM: loop closures against earlier keyframes.
  if (filter && options_.loop_closure.enabled && k % static_cast<size_t>(options_.loop_closure.every_n_keyframes) == 0)
    searchLoopClosures(k);
}

void Pipeline::localScanMatching(const io::LaserScan& scan, common::Pose2& z, Eigen::Matrix3d& cov) {
  const alignment::PriorMatchResult r = matchSubmap(scan, z, cov);
  if (!r.valid) {
    ++stats_.scan_matches_rejected;
    return;
  }
  ++stats_.scan_matches_used;
  // The posterior of the increment given the odometry and the scan replaces the odometry's.
  z = r.pose;
  cov = options_.local.covariance_scale * r.cov;
  const double sxy = options_.local.min_sigma_xy_m, sphi = options_.local.min_sigma_phi_deg * kDeg;
  cov(0, 0) = std::max(cov(0, 0), sxy * sxy);
  cov(1, 1) = std::max(cov(1, 1), sxy * sxy);
  cov(2, 2) = std::max(cov(2, 2), sphi * sphi);
}

void Pipeline::anchorScan(const io::LaserScan& scan) {
  // A scan between keyframes: its submap match places it relative to the last keyframe, for the
  // trajectory at odometry times only (the filter keeps one pose per keyframe).
  Eigen::Matrix3d cov = motion_.covariance();
  cov.diagonal() += Eigen::Vector3d(1e-8, 1e-8, 1e-10);
  const alignment::PriorMatchResult r = matchSubmap(scan, motion_.increment(), cov);
  if (!r.valid) return;
  ++stats_.scans_anchored;
  addAnchor({scan.timestamp, keyframes_.size() - 1, r.pose, motion_.odometryPose()});
}

alignment::PriorMatchResult Pipeline::matchSubmap(const io::LaserScan& scan, const common::Pose2& z, const Eigen::Matrix3d& cov) const {
  std::vector<common::Pose2> poses;
  for (size_t i = keyframes_.size() - std::min(keyframes_.size(), submap_.size()); i < keyframes_.size(); ++i)
    poses.push_back(keyframes_[i].pose);
  return submap_.match(scan, z, cov, poses);
}

void Pipeline::addAnchor(const ScanAnchor& anchor) {
  anchors_.push_back(anchor);
  // Odometry readings taken at the scan's time hang from it: the trajectory at that time is the
  // scan's pose, not the odometry prediction from the anchor before.
  for (auto it = odometry_.rbegin(); it != odometry_.rend() && it->timestamp == anchor.timestamp; ++it) it->anchor = anchors_.size() - 1;
}

void Pipeline::reportClosure(const LoopClosureRecord& r) {
  ++(r.accepted ? stats_.closures_accepted : stats_.closures_rejected);
  closures_.push_back(r);
  const LoopClosureEvent e{r.from, r.to, r.to_time, r.detector, r.score, r.accepted, r.reason};
  for (auto* o : observers_) o->onLoopClosure(e);
}

// Two closures confirm each other when the first, carried along the trajectory, predicts the
// second: between(x_j, x_i) ⊕ z_ik ⊕ between(x_k, x_m) ≈ z_jm. A wrong match in a symmetric
// building rarely repeats consistently at the next keyframe; a true one does.
bool Pipeline::consistent(const LoopClosureRecord& a, const LoopClosureRecord& b) const {
  // Two alignments onto the same earlier scan would repeat one aliasing (a corridor, a symmetric
  // room) rather than confirm it: the confirmation aligns with another scan of the earlier visit.
  if (a.from == b.from) return false;
  const auto& kf = keyframes_;
  const common::Pose2 predicted =
      common::compose(common::compose(common::between(kf[b.from].pose, kf[a.from].pose), a.measurement),
                      common::between(kf[a.to].pose, kf[b.to].pose));
  const common::Pose2 d = common::between(predicted, b.measurement);
  return std::hypot(d.x, d.y) <= options_.loop_closure.confirm_tolerance_m &&
         std::abs(d.phi) <= options_.loop_closure.confirm_tolerance_deg * kDeg;
}

void Pipeline::expirePending(size_t current) {
  // Hypotheses that waited too long for a confirmation are dropped.
  const size_t window = static_cast<size_t>(options_.loop_closure.confirm_window);
  while (!pending_.empty() && current - pending_.front().to > window) {
    LoopClosureRecord r = pending_.front();
    pending_.pop_front();
    r.accepted = false;
    r.reason = "unconfirmed";
    reportClosure(r);
  }
}

Pipeline::Admission Pipeline::admit(LoopClosureRecord r, size_t current) {
  const size_t window = static_cast<size_t>(options_.loop_closure.confirm_window);
  if (!r.accepted) {
    reportClosure(r);
    return Admission::Rejected;
  }
  if (window == 0) {  // tryClose already added it to the filter
    edges_.push_back({r.from, current, r.measurement, r.information, true});
    reportClosure(r);
    return Admission::Accepted;
  }
  // Confirmation by an earlier hypothesis that this one agrees with: both go in, gated again
  // against the current state. The second is gated after the first's information is added but
  // before the means move (no recovery in between), so when the first corrects a large drift
  // the second usually fails with a huge distance and only the first goes in. Gating both
  // before either goes in (what "current state" suggests) was measured worse: false closures
  // campus 4 -> 6, ACES 3 -> 6, CSAIL 1 -> 2 at the same ATE.
  auto match = std::find_if(pending_.begin(), pending_.end(),
                            [&](const LoopClosureRecord& p) { return p.to < current && consistent(p, r); });
  if (match == pending_.end()) {
    if (pending_.size() < 4 * window) pending_.push_back(r);
    return Admission::Pending;
  }
  LoopClosureRecord first = *match;
  pending_.erase(match);
  bool accepted = false;
  for (LoopClosureRecord* c : {&first, &r}) {
    const auto res = esdf_->observeRelative(static_cast<int>(c->from), static_cast<int>(c->to), esdf::toVec(c->measurement),
                                            c->information, true);
    c->accepted = res.accepted;
    c->mahalanobis2 = res.gate.mahalanobis2;
    if (!res.accepted) c->reason = "gating";
    if (c->accepted) {
      edges_.push_back({c->from, c->to, c->measurement, c->information, true});
      accepted = true;
    }
    reportClosure(*c);
  }
  return accepted ? Admission::Accepted : Admission::Rejected;
}

void Pipeline::searchLoopClosures(size_t current) {
  common::Stopwatch sw;
  expirePending(current);
  // 6. Candidates: initial set near the estimate, final set by Mahalanobis distance (keyframes
  // with scans only: alignment needs both).
  std::vector<size_t> cands;
  if (keyframes_[current].hasScan()) cands = closer_.candidates(*esdf_, keyframes_, current);
  cands.erase(std::remove_if(cands.begin(), cands.end(), [&](size_t i) { return !keyframes_[i].hasScan(); }), cands.end());
  if (cands.size() > static_cast<size_t>(options_.loop_closure.max_candidates))
    cands.resize(static_cast<size_t>(options_.loop_closure.max_candidates));
  for (auto* o : observers_) o->onCandidates({current, &cands});
  const bool confirm = options_.loop_closure.confirm_window > 0;
  bool accepted = false;
  for (size_t i : cands) {
    // 7-9. Detection, alignment and gating (the update itself waits for a confirmation).
    ++stats_.closures_tried;
    if (admit(closer_.tryClose(*esdf_, keyframes_, i, current, !confirm), current) == Admission::Accepted) {
      accepted = true;
      break;  // one closure per keyframe; the next keyframe sees the corrected map
    }
  }
  // 10. Full recovery after a closure (with relinearisation), then the corrected poses.
  if (accepted) recoverAll();
  stats_.closure_ms.push_back(sw.milliseconds());
}

void Pipeline::recoverAll() {
  esdf_->recover();
  std::vector<common::Pose2> poses(keyframes_.size());
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    keyframes_[i].pose = esdf::toPose(esdf_->mean(static_cast<int>(i)));
    poses[i] = keyframes_[i].pose;
  }
  closer_.rebuildIndex(keyframes_);
  dirty_since_recovery_ = false;
  for (auto* o : observers_) o->onPosesUpdated({&poses});
}

std::vector<io::StampedPose> Pipeline::odometryTrajectory() const {
  std::vector<io::StampedPose> out;
  out.reserve(odometry_.size());
  const auto anchorPose = [&](const ScanAnchor& a) { return common::compose(keyframes_[a.keyframe].pose, a.offset); };
  const auto via = [&](size_t i, const common::Pose2& odom) {
    return common::compose(anchorPose(anchors_[i]), common::between(anchors_[i].odom, odom));
  };
  for (const auto& s : odometry_) {
    if (anchors_.empty()) break;
    // Before the first keyframe the map frame is the odometry frame of that keyframe.
    const size_t a = s.anchor == kNone || s.anchor >= anchors_.size() ? 0 : s.anchor;
    common::Pose2 p = via(a, s.odom);
    // Between two anchors (keyframes or matched scans), the odometry drift is spread over the
    // interval: the pose from the earlier anchor forwards and from the later one backwards,
    // blended by time.
    const size_t b = a + 1;
    if (s.anchor != kNone && b < anchors_.size()) {
      const double ta = anchors_[a].timestamp, tb = anchors_[b].timestamp;
      if (tb > ta) {
        const double f = std::clamp((s.timestamp - ta) / (tb - ta), 0.0, 1.0);
        p = common::interpolate(p, via(b, s.odom), f);
      }
    }
    out.push_back({s.timestamp, p});
  }
  // In time order for TUM readers: the Intel log writes about one odometry reading in 20 out of
  // time order.
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  // One pose per timestamp: the Freiburg campus log has no timestamps, so the reader gives every
  // odometry reading between two scans the next scan's time (up to 15 readings, a metre apart),
  // and a reader of the file looking that time up would get whichever it finds first. The last
  // one read is the state at that time; when a scan has that time it is the scan's own pose
  // (readings stamped with a scan's time hang from its anchor and come before it).
  const auto last = std::unique(out.rbegin(), out.rend(), [](const auto& a, const auto& b) { return a.timestamp == b.timestamp; });
  out.erase(out.begin(), last.base());
  // The scans placed by matching are poses of this trajectory too, so that at a scan's time it
  // is that scan's pose (a reading with the same stamp gives way: the Intel log's stamps go back
  // and forth, 2661.47, scan, 2661.07, 2661.14, 2661.47, and the pose there is the scan's, not
  // that later reading's) and between scans it moves with the odometry from one to the next.
  const auto scans = scanTrajectory();
  std::vector<io::StampedPose> merged;
  merged.reserve(out.size() + scans.size());
  auto o = out.begin();
  for (const auto& a : scans) {
    for (; o != out.end() && o->timestamp <= a.timestamp; ++o)
      if (o->timestamp < a.timestamp) merged.push_back(*o);
    if (merged.empty() || merged.back().timestamp != a.timestamp) merged.push_back(a);
  }
  merged.insert(merged.end(), o, out.end());
  return merged;
}

std::vector<io::StampedPose> Pipeline::scanTrajectory() const {
  std::vector<io::StampedPose> out;
  out.reserve(anchors_.size());
  for (const auto& a : anchors_) out.push_back({a.timestamp, common::compose(keyframes_[a.keyframe].pose, a.offset)});
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  return out;
}

std::vector<io::PosedScan> Pipeline::posedKeyframes() const {
  std::vector<io::PosedScan> out;
  out.reserve(keyframes_.size());
  for (const auto& k : keyframes_) out.push_back({k.pose, &k.scan});
  return out;
}

}  // namespace urbanslam::slam
