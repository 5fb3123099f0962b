#include "urbanslam/slam/GlobalSlam.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/slam/MovingReturns.h"

namespace urbanslam::slam {

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

GlobalSlam::GlobalSlam(const PipelineOptions& options, Map& map, PipelineStats& stats, const std::vector<PipelineObserver*>& observers)
    : options_(options),
      map_(map),
      stats_(stats),
      observers_(observers),
      closer_(options.loop_closure),
      closures_("loop closure records", options.map.scan_spill_dir) {
  if (options_.loop_closure.enabled && options_.loop_closure.detector == LoopClosureOptions::Detector::Laser) {
    // The AdaBoost classifier adds candidates where the estimate is too uncertain to pick them. Its
    // score is the margin above the model's decision factor (eq. 3.30), so laser_threshold = 0
    // is the model's own operating point. Configured models are read now, so that a bad file
    // stops the run before it starts; which one is used (laserModelFor: whether the laser sees
    // all around) is decided at the first use, from the first keyframe's scan.
    for (const std::string* path : {&options_.loop_closure.laser_model, &options_.loop_closure.laser_model_360})
      if (!path->empty()) laser_loop::loadModel(*path);
    closer_.setScorer([this](size_t earlier, size_t current) {
      laser_loop::LoopDetector& d = laserDetector();
      return d.score(current, earlier) - d.factor();
    });
  }
}

laser_loop::LoopDetector& GlobalSlam::laserDetector() {
  if (!laser_detector_) {
    size_t first = 0;
    while (first + 1 < map_.size() && !map_.keyframes()[first].hasScan()) ++first;
    const io::LaserScan scan = map_.size() > 0 ? map_.scan(first) : io::LaserScan{};
    laser_detector_ =
        std::make_unique<laser_loop::LoopDetector>(laser_loop::LoopDetector::fromFile(laserModelFor(options_.loop_closure, scan)));
  }
  // Features are a function of each keyframe's scan, computed once, when first needed (the
  // indoor logs never need them; a resumed run computes them from the saved scans).
  for (size_t k = laser_detector_->size(); k < map_.size(); ++k) laser_detector_->addKeyframe(map_.scan(k));
  return *laser_detector_;
}

GlobalSlam::~GlobalSlam() = default;

std::array<double, 9> GlobalSlam::addKeyframe(Keyframe kf, io::CompactScan scan, const KeyframeConstraint& constraint) {
  return addKeyframeFrom(map_.empty() ? 0 : map_.size() - 1, std::move(kf), std::move(scan), constraint);
}

std::array<double, 9> GlobalSlam::addKeyframeFrom(size_t from, Keyframe kf, io::CompactScan scan, const KeyframeConstraint& constraint) {
  const size_t k = map_.size();
  esdf::Esdf* filter = map_.filter();
  KeyframeNodes* nodes = map_.nodes();
  if (k == 0) {
    // The first keyframe anchors the map at the origin.
    if (filter) {
      filter->initialise(esdf::Vec3::Zero(), esdf::Mat3::Identity() * 1e-9);
      nodes->addFirst();
    }
  } else {
    const Eigen::Matrix3d info = constraint.cov.inverse();
    map_.addEdge({from, k, constraint.z, info, false});
    if (filter) {
      // ESDF prediction with augmentation: the keyframe becomes a delayed pose, O(1); then the
      // recent poses are recovered (a bounded window: constant time between closures). In a
      // reduced pose graph three keyframes in four hang from the newest pose instead, the filter
      // unchanged.
      if (nodes->add(from, esdf::toVec(constraint.z), info)) {
        filter->recoverRecent(std::max(0, filter->size() - 1 - options_.estimator.recent_window));
        dirty_since_recovery_ = true;
      }
    }
  }
  kf.pose = filter ? esdf::toPose(nodes->mean(k)) : (k == 0 ? common::Pose2{} : common::compose(map_.keyframes()[from].pose, constraint.z));
  // Window recovery moved the last `recent_window` keyframes too.
  const size_t window = static_cast<size_t>(options_.estimator.recent_window);
  if (filter && k > 0) map_.pullPoses(k > window ? k - window : 0);
  map_.addKeyframe(std::move(kf), std::move(scan));
  std::array<double, 9> c{};
  if (filter && k > 0) {
    const esdf::Mat3 m = nodes->marginalCovariance(k, esdf::CovarianceMode::Conservative);
    for (int i = 0; i < 9; ++i) c[static_cast<size_t>(i)] = m(i / 3, i % 3);
  }
  return c;
}

void GlobalSlam::finish() {
  closePendingLoops(std::chrono::steady_clock::now());
  for (LoopClosureRecord r : pending_) reportExpired(r);  // hypotheses still waiting for a confirmation
  pending_.clear();
  if (dirty_since_recovery_) recoverAll(true);
}

void GlobalSlam::closureAdded(size_t current, SteadyTime handed_over) {
  if (!unrecovered_closure_) unrecovered_closure_ = std::make_pair(current, handed_over);
  // A full recovery costs O(n) and more (a factorisation of the whole map): after a closure
  // only once the map has grown by a fraction of what it was at the last one, which spreads its
  // cost over that many keyframes, so that the cost per keyframe grows only as a factorisation's
  // cost per pose does; and only once those keyframes have paid for its work at
  // full_recovery_work_per_keyframe each, which bounds that cost where the factor fills faster
  // than the map grows (every pass of a city's streets linked to the earlier ones). Between
  // them the closure's information is in the filter, and the recent poses (where the next
  // candidates and closures are) are recovered.
  const double growth = options_.estimator.full_recovery_min_growth, work = options_.estimator.full_recovery_work_per_keyframe;
  const double since = static_cast<double>(map_.size() - last_full_size_);
  if (since >= growth * static_cast<double>(last_full_size_) && (work <= 0 || since * work >= map_.filter()->recoveryWork())) {
    recoverAll(false);
    added_.clear();
    return;
  }
  recoverRecent();
  // A window recovery moves only the newest poses. The first closure of a long loop corrects a
  // drift of metres that they cannot take up: the mean then still misses the closure, while the
  // exact covariance, with its information in, has shrunk to centimetres. The loop's next
  // closures would be gated against that stale mean and refused, and a wrong alignment that
  // happens to fit it admitted (on the 1,000 km drive this lost the map). So a closure the
  // recovered mean still misses by more than the gate brings the whole map's recovery now.
  if (missesAddedClosure()) recoverAll(false);
  added_.clear();
}

bool GlobalSlam::missesAddedClosure() const {
  const KeyframeNodes& nodes = *map_.nodes();
  const double threshold = map_.filter()->gateThreshold();
  for (const LoopClosureRecord& c : added_) {
    // A closure through a hung keyframe's offsets goes in with a share of their information, or
    // none once they are spent (KeyframeNodes): its own information does not tell what the mean
    // owes it.
    if (nodes.hung(c.from) || nodes.hung(c.to)) continue;
    const esdf::Vec3 e = esdf::relativePoseError(nodes.mean(c.from), nodes.mean(c.to), esdf::toVec(c.measurement));
    if (e.dot(c.information * e) > threshold) return true;
  }
  return false;
}

void GlobalSlam::recoverRecent() {
  const int window = options_.estimator.recent_window;
  const int nodes = map_.filter()->size();
  map_.filter()->recoverRecent(nodes > window ? nodes - window : 0);
  const size_t first = map_.size() > static_cast<size_t>(window) ? map_.size() - static_cast<size_t>(window) : 0;
  map_.pullPoses(first);
}

void GlobalSlam::reportClosure(const LoopClosureRecord& r) {
  ++(r.accepted ? stats_.closures_accepted : stats_.closures_rejected);
  if (r.accepted) added_.push_back(r);
  keepIfNewestAccepted(r);
  closures_.push_back(r);
  const LoopClosureEvent e{r.from, r.to, r.to_time, r.detector, r.score, r.accepted, reasonName(r.reason)};
  for (auto* o : observers_) o->onLoopClosure(e);
}

// Two closures confirm each other when the first, carried along the trajectory, predicts the
// second: between(x_j, x_i) ⊕ z_ik ⊕ between(x_k, x_m) ≈ z_jm. A wrong match in a symmetric
// building rarely repeats consistently at the next keyframe; a true one does.
bool GlobalSlam::consistent(const LoopClosureRecord& a, const LoopClosureRecord& b) const {
  // Two alignments onto the same earlier scan would repeat one aliasing (a corridor, a symmetric
  // room) rather than confirm it: the confirmation aligns with another scan of the earlier visit.
  if (a.from == b.from) return false;
  return agree(carriedClosure(map_, a, b.from, b.to), b.measurement);
}

bool GlobalSlam::agree(const common::Pose2& a, const common::Pose2& b) const {
  const common::Pose2 d = common::between(a, b);
  return std::hypot(d.x, d.y) <= options_.loop_closure.confirm_tolerance_m &&
         std::abs(d.phi) <= options_.loop_closure.confirm_tolerance_deg * kDeg;
}

void GlobalSlam::expirePending(size_t current) {
  // Hypotheses that waited too long for a confirmation are dropped.
  const size_t window = static_cast<size_t>(options_.loop_closure.confirm_window);
  while (!pending_.empty() && current - pending_.front().to > window) {
    reportExpired(pending_.front());
    pending_.pop_front();
  }
}

void GlobalSlam::reportExpired(LoopClosureRecord r) {
  // One that passed the gate was unconfirmed; one that waited for a joint gate stays refused by
  // the gate (its reason already).
  if (r.accepted) r.reason = ClosureReason::Unconfirmed;
  r.accepted = false;
  reportClosure(r);
}

bool GlobalSlam::waitsForJointGate(const LoopClosureRecord& r) const {
  if (!options_.loop_closure.joint_gate || r.accepted || r.reason != ClosureReason::Gating) return false;
  return r.mahalanobis2 <= map_.nodes()->jointGateThreshold();
}

void GlobalSlam::keepIfNewestAccepted(const LoopClosureRecord& r) {
  if (r.accepted && (!last_accepted_ || r.to >= last_accepted_->to)) last_accepted_ = r;
}

const LoopClosureRecord* GlobalSlam::recentClosure(size_t current) const {
  const size_t window = static_cast<size_t>(std::max(1, options_.loop_closure.confirm_window));
  const LoopClosureRecord* c = last_accepted_ ? &*last_accepted_ : nullptr;
  return c && !c->restarts_skipped && c->to < current && current - c->to <= window ? c : nullptr;
}

bool GlobalSlam::confirming() const {
  return std::any_of(pending_.begin(), pending_.end(), [](const LoopClosureRecord& p) { return p.accepted; });
}

// A closure refused by the gate alone, by less than two closures' quantile, waits for a later one
// that agrees with it (consistent) and was refused alike; the two go in when their joint gate
// passes (Esdf::gateRelativePair), with no gate of their own.
GlobalSlam::Admission GlobalSlam::admitJointly(LoopClosureRecord r, size_t current) {
  auto match = std::find_if(pending_.begin(), pending_.end(),
                            [&](const LoopClosureRecord& p) { return !p.accepted && p.to < current && consistent(p, r); });
  if (match != pending_.end()) {
    const esdf::GateResult joint =
        map_.nodes()->gateRelativePair(match->from, match->to, esdf::toVec(match->measurement), match->information, r.from, r.to,
                                       esdf::toVec(r.measurement), r.information);
    if (joint.accepted) {
      LoopClosureRecord first = *match;
      pending_.erase(match);
      for (LoopClosureRecord* c : {&first, &r}) {
        map_.nodes()->observeRelative(c->from, c->to, esdf::toVec(c->measurement), c->information, false);
        map_.addEdge({c->from, c->to, c->measurement, c->information, true});
        c->accepted = true;
        c->reason = ClosureReason::None;
        c->confirmed_by = Confirmation::Jointly;
        c->mahalanobis2 = joint.mahalanobis2;
        c->gate_threshold = joint.threshold;
        reportClosure(*c);
      }
      return Admission::Accepted;
    }
  }
  if (pending_.size() < 4 * static_cast<size_t>(options_.loop_closure.confirm_window)) {
    pending_.push_back(r);
    return Admission::Pending;
  }
  reportClosure(r);
  return Admission::Rejected;
}

GlobalSlam::Admission GlobalSlam::admit(LoopClosureRecord r, size_t current, MeasuredBy measured,
                                        const std::optional<CameraPairView>& view) {
  const size_t window = static_cast<size_t>(options_.loop_closure.confirm_window);
  if (contradicts_join_ && (r.reason == ClosureReason::None || r.reason == ClosureReason::Gating) && contradicts_join_(r)) {
    r.accepted = false;
    r.reason = ClosureReason::Join;
    reportClosure(r);
    return Admission::Rejected;
  }
  if (window > 0 && waitsForJointGate(r)) return admitJointly(std::move(r), current);
  if (!r.accepted) {
    reportClosure(r);
    return Admission::Rejected;
  }
  if (window == 0) {
    if (!closerCommits()) return commit({&r});                            // gated, not yet added: the join check came first
    map_.addEdge({r.from, current, r.measurement, r.information, true});  // tryClose added it to the filter
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
                            [&](const LoopClosureRecord& p) { return p.accepted && p.to < current && consistent(p, r); });
  if (match != pending_.end()) {
    LoopClosureRecord first = *match;
    pending_.erase(match);
    first.confirmed_by = r.confirmed_by = Confirmation::Closure;
    return commit({&first, &r});
  }
  // Or by the other sensor: the images of the two places measure what the scans did.
  if (measured == MeasuredBy::Scans && cameraConfirms(r, view)) {
    r.confirmed_by = Confirmation::Camera;
    return commit({&r});
  }
  if (pending_.size() < 4 * window) {
    pending_.push_back(r);
    return Admission::Pending;
  }
  // No room to wait: unconfirmed now, and on record as such.
  reportExpired(std::move(r));
  return Admission::Rejected;
}

bool GlobalSlam::closerCommits() const { return options_.loop_closure.confirm_window == 0 && !contradicts_join_; }

GlobalSlam::Admission GlobalSlam::commit(std::initializer_list<LoopClosureRecord*> records) {
  bool accepted = false;
  for (LoopClosureRecord* c : records) {
    const auto res = map_.nodes()->observeRelative(c->from, c->to, esdf::toVec(c->measurement), c->information, true);
    c->accepted = res.accepted;
    c->mahalanobis2 = res.gate.mahalanobis2;
    if (!res.accepted) {
      c->reason = ClosureReason::Gating;
      c->confirmed_by = Confirmation::None;
    }
    if (c->accepted) {
      map_.addEdge({c->from, c->to, c->measurement, c->information, true});
      accepted = true;
    }
    reportClosure(*c);
  }
  return accepted ? Admission::Accepted : Admission::Rejected;
}

// The camera confirms a closure that the scans measured when the images nearest its two
// keyframes give the same full relative pose, the closure carried to the images' keyframes by the
// estimate (they are at most a few keyframes from the closure's, a few centimetres of odometry):
// the same agreement as two closures' (consistent). Bearing and heading alone leave the length
// along the baseline open, which is where a street's repeated facades put a wrong alignment, so
// they confirm nothing.
bool GlobalSlam::cameraConfirms(const LoopClosureRecord& r, const std::optional<CameraPairView>& given) const {
  if (!options_.loop_closure.camera_confirmation || r.bearing_only) return false;
  const std::optional<CameraPairView> view = given ? given : camera_measurer_ ? camera_measurer_(r.from, r.to) : std::nullopt;
  if (!view || !view->camera.metric.valid) return false;
  const common::Pose2 scans = carriedClosure(map_, r, view->earlier, view->current);
  const common::Pose2& m = view->camera.mount;
  return agree(common::compose(common::compose(m, view->camera.metric.pose), common::inverse(m)), scans);
}

size_t GlobalSlam::searchLag() const { return static_cast<size_t>(std::max(0, options_.loop_closure.moving_returns_neighbours)); }

void GlobalSlam::closeLoops(size_t newest, SteadyTime handed_over) {
  if (map_.filter() && searchLag() > 0) {
    MovingReturnsOptions o;  // the loop closer's judges' margins and widths
    const auto pose = [&](size_t j) { return esdf::toPose(map_.nodes()->mean(j)); };
    if (seesThroughEarlier(map_, newest, searchLag(), pose, o)) waiting_.push_back(newest);
  }
  while (next_search_ <= newest) {
    if (!waiting_.empty() && waiting_.front() == next_search_) {
      if (next_search_ + searchLag() > newest) break;
      waiting_.pop_front();
    }
    searchLoopsEvery(next_search_++, handed_over);
  }
}

void GlobalSlam::closePendingLoops(SteadyTime handed_over) {
  for (; next_search_ < map_.size(); ++next_search_) searchLoopsEvery(next_search_, handed_over);
  waiting_.clear();
}

void GlobalSlam::searchLoopsEvery(size_t current, SteadyTime handed_over) {
  const LoopClosureOptions& o = options_.loop_closure;
  if (!map_.filter() || !o.enabled || current % static_cast<size_t>(o.every_n_keyframes) != 0) return;
  if (alongRevisit(current)) return;
  searchLoops(current, handed_over);
}

bool GlobalSlam::alongRevisit(size_t current) const {
  // The newest closure is at most n-1 keyframes back: the next is at the n-th (a hypothesis that
  // waits for its confirmation is searched at every keyframe, or it expires).
  const size_t n = static_cast<size_t>(options_.loop_closure.revisit_every_n_keyframes);
  return last_accepted_ && last_accepted_->to < current && current - last_accepted_->to < n && !confirming();
}

void GlobalSlam::searchLoops(size_t current, SteadyTime handed_over) {
  common::Stopwatch sw;
  expirePending(current);
  // 6. Candidates: initial set near the estimate, final set by Mahalanobis distance, and where
  // the estimate is too uncertain the classifier's detections (keyframes with scans only:
  // alignment needs both).
  std::vector<Candidate> cands;
  if (map_.keyframes()[current].hasScan()) cands = closer_.candidates(*map_.nodes(), map_, current, confirming());
  std::vector<size_t> keyframes;
  for (const Candidate& c : cands) keyframes.push_back(c.keyframe);
  for (auto* o : observers_) o->onCandidates({current, &keyframes});
  bool accepted = false;
  for (const Candidate& c : cands) {
    // 7-9. Alignment and gating (the update itself waits for a confirmation).
    ++stats_.closures_tried;
    const Detection* detection = c.detection ? &*c.detection : nullptr;
    if (admit(closer_.tryClose(*map_.nodes(), map_, c.keyframe, current, closerCommits(), detection, recentClosure(current)), current) ==
        Admission::Accepted) {
      accepted = true;
      break;  // one closure per keyframe; the next keyframe sees the corrected map
    }
  }
  // 10. Recovery after a closure: the whole map (with relinearisation) when it has grown enough
  //     since the last, else the recent poses.
  if (accepted) closureAdded(current, handed_over);
  stats_.closure_ms.add(sw.milliseconds());
}

void GlobalSlam::addPlaceFix(size_t earlier, size_t current, const common::Pose2& z, const Eigen::Matrix3d& information, double score,
                             Proposer detector) {
  if (!map_.filter()) return;
  ++stats_.closures_tried;
  const Detection detection{detector, score};
  // The place search matched the scan against a whole area's grid: it recognised the place. The
  // two keyframes' scans, aligned from there, measure it as a loop closure does (in an ACES
  // corridor a search settled 1.2 m along it, held to 2 cm, and the closures that followed were
  // gated out). CRF-match first, ICP then from its hypotheses and the fix: PL-ICP from a fix a
  // metre off stops in a wrong minimum. No ambiguity restarts (a reach of 0 leaves them none):
  // the join's agreeing fixes have told the place already; the innovation gate below judges the
  // measurement as any closure's.
  common::Pose2 measured = z;
  Eigen::Matrix3d measured_information = information;
  if (detector == Proposer::Place) {
    LoopClosureRecord check;
    const alignment::AlignmentResult a =
        closer_.verifyAlignment(map_.scan(earlier), map_.scan(current), z, alignment::Method::CrfIcp, 0.0, check);
    if (check.reason == ClosureReason::None) {
      measured = a.transform;
      measured_information = (options_.loop_closure.covariance_scale * a.cov).inverse();
    }
  }
  LoopClosureRecord r =
      closer_.tryCloseMeasured(*map_.nodes(), map_, earlier, current, esdf::toVec(measured), measured_information, true, detection);
  if (r.accepted) map_.addEdge({earlier, current, r.measurement, r.information, true});
  reportClosure(r);
  if (r.accepted) closureAdded(current, std::chrono::steady_clock::now());
}

void GlobalSlam::recoverAll(bool converge) {
  common::Stopwatch sw;
  // Each Gauss-Newton step is a factorisation of the whole map, superlinear in its size. A
  // recovery after a closure takes a fixed number of them and leaves relinearising what they
  // moved to the next recovery: relinearising at its end would leave the factor stale, and the
  // next closure's exact gate would pay another factorisation for it.
  map_.filter()->relinearise();
  if (converge)
    map_.filter()->recover();
  else
    map_.filter()->recover(options_.estimator.full_recovery_steps - 1);
  last_full_size_ = map_.size();
  map_.pullPoses(0);
  map_.reindex();
  std::vector<common::Pose2> poses;
  poses.reserve(map_.size());
  for (const auto& k : map_.keyframes()) poses.push_back(k.pose);
  // What a recovery stopped short of (at least the relinearisation it left), the run's last owes.
  dirty_since_recovery_ = !converge;
  PosesUpdatedEvent e{&poses};
  e.recovery_ms = sw.milliseconds();
  e.map_factorisations = map_.filter()->factorisations();
  e.filter_poses = map_.filter()->size();
  if (unrecovered_closure_) {
    e.keyframe = unrecovered_closure_->first;
    e.latency_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - unrecovered_closure_->second).count();
    stats_.global_latency_ms.add(e.latency_ms);
    unrecovered_closure_.reset();
  }
  for (auto* o : observers_) o->onPosesUpdated(e);
}

bool GlobalSlam::allowsFullCameraPose(size_t earlier, size_t current) {
  KeyframeNodes* f = map_.nodes();
  return f && esdf::largestPositionSigma(closer_.relativeCovariance(*f, earlier, current)) <= options_.loop_closure.appearance_min_sigma_m;
}

void GlobalSlam::proposeImageClosure(size_t earlier, size_t current, double score, const std::optional<CameraMeasurement>& camera,
                                     SteadyTime handed_over) {
  ++stats_.image_proposals;
  ImageMatchEvent ev{current, earlier, score, false, ""};
  const bool filter = map_.filter() != nullptr;
  const bool scans = map_.keyframes()[earlier].hasScan() && map_.keyframes()[current].hasScan();
  const bool measured = camera && camera->relative.valid;
  if (filter && options_.loop_closure.enabled && (scans || measured)) {
    // The same path as a laser candidate: alignment of the scans when both keyframes have one,
    // else the camera's own relative pose; then gating and confirmation by a second closure.
    common::Stopwatch sw;
    expirePending(current);
    const Detection detection{Proposer::Image, score};
    KeyframeNodes& f = *map_.nodes();
    LoopClosureRecord r;
    std::optional<CameraPairView> view;
    if (scans) {
      r = closer_.tryClose(f, map_, earlier, current, closerCommits(), &detection, recentClosure(current));
      if (camera) view = CameraPairView{earlier, current, *camera};
    } else {
      CameraMeasurement m = *camera;
      if (m.metric.valid && !allowsFullCameraPose(earlier, current)) m.metric.valid = false;
      const esdf::RelativeFactor factor = cameraFactor(m, f.mean(earlier), f.mean(current));
      r = closer_.tryCloseMeasured(f, map_, earlier, current, factor.z, factor.omega, closerCommits(), detection, &m);
    }
    ++stats_.closures_tried;
    const ClosureReason reason = r.reason;
    const Admission a = admit(std::move(r), current, scans ? MeasuredBy::Scans : MeasuredBy::Camera, view);
    ev.accepted = a == Admission::Accepted;
    ev.fate = a == Admission::Accepted  ? "accepted"
              : a == Admission::Pending ? "pending"
                                        : (reason == ClosureReason::None ? "gating" : reasonName(reason));
    if (ev.accepted) closureAdded(current, handed_over);
    stats_.closure_ms.add(sw.milliseconds());
  } else {
    // Neither scans nor a camera relative pose (or no filter): a proposal on record, never a
    // constraint.
    LoopClosureRecord r;
    r.from = earlier;
    r.to = current;
    r.from_time = map_.keyframes()[earlier].timestamp;
    r.to_time = map_.keyframes()[current].timestamp;
    r.detector = Proposer::Image;
    r.score = score;
    r.reason = !filter                          ? ClosureReason::NoFilter
               : !options_.loop_closure.enabled ? ClosureReason::LoopClosureDisabled
               : camera                         ? ClosureReason::CameraGeometry
                                                : ClosureReason::NoScans;
    ev.fate = reasonName(r.reason);
    reportClosure(r);
  }
  for (auto* o : observers_) o->onImageMatch(ev);
}

}  // namespace urbanslam::slam
