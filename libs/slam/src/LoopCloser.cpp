#include "urbanslam/slam/LoopCloser.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/FreeSpace.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/ShiftedRestarts.h"
#include "urbanslam/esdf/Gating.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/PathSubmaps.h"

namespace urbanslam::slam {

namespace {
// The free-space test of two scans as [loop_closure] configures it (alignment/FreeSpace.h).
alignment::FreeSpaceOptions freeSpaceOptions(const LoopClosureOptions& o) {
  alignment::FreeSpaceOptions fo;
  fo.margin_m = o.free_space_margin_m;
  fo.no_return_free_m = o.free_space_no_return_m;
  return fo;
}
}  // namespace

const char* reasonName(ClosureReason reason) {
  switch (reason) {
    case ClosureReason::None:
      return "";
    case ClosureReason::Alignment:
      return "alignment";
    case ClosureReason::Ambiguous:
      return "ambiguous";
    case ClosureReason::FreeSpace:
      return "free_space";
    case ClosureReason::Gating:
      return "gating";
    case ClosureReason::Unconfirmed:
      return "unconfirmed";
    case ClosureReason::NoScans:
      return "no_scans";
    case ClosureReason::CameraGeometry:
      return "camera_geometry";
    case ClosureReason::NoFilter:
      return "no_filter";
    case ClosureReason::LoopClosureDisabled:
      return "loop_closure_disabled";
    case ClosureReason::NoOverlap:
      return "no_overlap";
    case ClosureReason::Submaps:
      return "submaps";
    case ClosureReason::SceneDepth:
      return "scene_depth";
    case ClosureReason::Join:
      return "join";
  }
  return "";
}

const char* confirmationName(Confirmation c) {
  switch (c) {
    case Confirmation::None:
      return "";
    case Confirmation::Closure:
      return "closure";
    case Confirmation::Camera:
      return "camera";
    case Confirmation::Jointly:
      return "jointly";
  }
  return "";
}

namespace {

MovingReturnsOptions movingReturnsOptions(const LoopClosureOptions& options) {
  MovingReturnsOptions o;
  o.neighbours = options.moving_returns_neighbours;
  return o;
}

}  // namespace

LoopCloser::LoopCloser(const LoopClosureOptions& options)
    : options_(options), chi2_2dof_(esdf::chi2Quantile(options.mahalanobis_probability, 2)), moving_(movingReturnsOptions(options)) {}

void LoopCloser::setScorer(CandidateScorer scorer) { scorer_ = std::move(scorer); }

// Covariance of the relative pose ⊖x_i ⊕ x_k from the (conservative) joint covariance. Kept for
// the current keyframe: the candidate search computes it, the alignment choice reuses it.
Eigen::Matrix3d LoopCloser::relativeCovariance(KeyframeNodes& filter, size_t i, size_t k) {
  if (cached_for_ != k) {
    cached_.clear();
    cached_for_ = k;
  }
  if (const auto it = cached_.find(i); it != cached_.end()) return it->second;
  const Eigen::Matrix3d s = filter.relativeCovariance(i, k, esdf::CovarianceMode::Conservative);
  cached_[i] = s;
  return s;
}

std::vector<Candidate> LoopCloser::candidates(KeyframeNodes& filter, const Map& map, size_t current, bool confirming) {
  const auto& keyframes = map.keyframes();
  const KeyframeGrid& grid = map.index();
  const auto& cur = keyframes[current];
  if (current < static_cast<size_t>(options_.min_keyframe_gap)) return {};
  const size_t newest_allowed = current - static_cast<size_t>(options_.min_keyframe_gap);
  // Initial set: earlier keyframes within the search radius, widened by the current pose's own
  // 3-sigma position uncertainty (conservative covariance: no refactorisation).
  const esdf::Mat3 c = filter.marginalCovariance(current, esdf::CovarianceMode::Conservative);
  const double sigma = esdf::largestPositionSigma(c);
  const double radius = options_.search_radius_m + 3 * sigma;
  std::vector<size_t> near;
  grid.query(cur.pose.x, cur.pose.y, radius, near);
  std::vector<std::pair<double, size_t>> initial;
  for (size_t i : near) {
    if (i > newest_allowed || !keyframes[i].hasScan()) continue;
    const double d = std::hypot(keyframes[i].pose.x - cur.pose.x, keyframes[i].pose.y - cur.pose.y);
    if (d <= radius) initial.emplace_back(d, i);
  }
  std::sort(initial.begin(), initial.end());
  // Final set: could the two poses be within the sensor's overlap distance, given their joint
  // uncertainty? d^2 = t' (J Σ J' + (R/2)^2 I)^-1 t for the relative position t.
  const double r2 = 0.25 * options_.search_radius_m * options_.search_radius_m;
  const auto mahalanobis2 = [&](size_t i) {
    const esdf::Vec3 xi = filter.mean(i), xk = filter.mean(current);
    const Eigen::Matrix3d s = relativeCovariance(filter, i, current);
    const Eigen::Matrix2d st = s.topLeftCorner<2, 2>() + r2 * Eigen::Matrix2d::Identity();
    const Eigen::Vector2d t = esdf::between(xi, xk).head<2>();
    return t.dot(st.inverse() * t);
  };
  // Where the map is: the uncertainty of the current pose relative to the nearest earlier
  // keyframe (its own marginal grows with the distance from the map's origin even where loops
  // have tied it to the keyframes around). Beyond appearance_min_sigma_m, more than alignment
  // from the estimate's guess reaches, the nearest keyframes are as likely wrong as any within
  // reach.
  const bool far = !initial.empty() && esdf::largestPositionSigma(relativeCovariance(filter, initial.front().second, current)) >
                                           options_.appearance_min_sigma_m;
  // The keyframes nearest the estimate, nearest in Mahalanobis distance first (the 30 nearest
  // tested: bounded covariance work per keyframe). Far from the map they are searched at every
  // n-th keyframe only: the next keyframe's nearest are the same wrong guesses shifted by a
  // keyframe, and CRF-match + ICP on each costs several milliseconds (in the 1 km² city, 7 of
  // the 1616 searches with a relative sigma beyond 3 m found a closure). While a hypothesis
  // waits for its confirmation every keyframe searches.
  constexpr size_t kMahalanobisTests = 30;
  std::vector<std::pair<double, size_t>> near_set;
  const bool search_near = !far || confirming || current % static_cast<size_t>(options_.far_every_n_keyframes) == 0;
  for (size_t n = 0; search_near && n < initial.size() && n < kMahalanobisTests; ++n)
    if (const double d2 = mahalanobis2(initial[n].second); d2 <= chi2_2dof_) near_set.emplace_back(d2, initial[n].second);
  std::sort(near_set.begin(), near_set.end());
  const size_t per_source = static_cast<size_t>(options_.max_candidates);
  std::vector<Candidate> out;
  for (size_t n = 0; n < near_set.size() && n < per_source; ++n) {
    size_t i = near_set[n].second;
    if (const auto partner = oppositeViewPartner(filter, map, i, current, newest_allowed)) i = *partner;
    const bool known = std::any_of(out.begin(), out.end(), [i](const Candidate& c) { return c.keyframe == i; });
    if (!known) out.push_back({i, std::nullopt});
  }
  // There the classifier's detections among all of them follow, best first and one per place, so
  // that an aliased place cannot take every slot.
  if (!scorer_ || !far || !cur.hasScan()) return out;
  std::vector<std::pair<double, size_t>> scored;
  for (const auto& [d, i] : initial)
    if (const double score = scorer_(i, current); score >= options_.laser_threshold) scored.emplace_back(score, i);
  std::sort(scored.begin(), scored.end(),
            [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  const size_t first_detection = out.size();
  for (const auto& [score, detected] : scored) {
    if (out.size() - first_detection == per_source) break;
    const size_t i = detected;  // a plain variable: lambdas cannot capture structured bindings before C++20 (clang)
    const auto same = [&](const Candidate& p) {
      return p.keyframe == i || (p.detection && std::hypot(keyframes[i].pose.x - keyframes[p.keyframe].pose.x,
                                                           keyframes[i].pose.y - keyframes[p.keyframe].pose.y) < options_.search_radius_m);
    };
    if (std::none_of(out.begin(), out.end(), same) && mahalanobis2(i) <= chi2_2dof_) out.push_back({i, Detection{Proposer::Laser, score}});
  }
  return out;
}

bool LoopCloser::headingOtherWay(const Map& map, const esdf::Vec3& xi, const esdf::Vec3& xk, size_t current) {
  if (options_.opposite_view_offset_m <= 0 || std::fabs(common::wrapToPi(xk(2) - xi(2))) <= M_PI / 2) return false;
  // A scan of (nearly) the whole circle sees the place from any heading. Read from the first
  // keyframe with a scan that gets here: one laser per run.
  if (!narrow_view_) {
    if (!map.keyframes()[current].hasScan()) return false;
    const io::LaserScan s = map.scan(current);
    narrow_view_ = static_cast<double>(s.size()) * s.angle_increment_rad < 1.5 * M_PI;
  }
  return *narrow_view_;
}

std::optional<size_t> LoopCloser::oppositeViewPartner(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current,
                                                      size_t newest_allowed) {
  const esdf::Vec3 xi = filter.mean(earlier), xk = filter.mean(current);
  if (!headingOtherWay(map, xi, xk, current)) return std::nullopt;
  // Where the current laser looks: ahead of the pose. The earlier visit saw that stretch from
  // behind it, i.e. before it reached `earlier`: walk along its keyframes (both ways, the path
  // may turn) while they approach that point.
  const double tx = xk(0) + options_.opposite_view_offset_m * std::cos(xk(2));
  const double ty = xk(1) + options_.opposite_view_offset_m * std::sin(xk(2));
  const auto dist = [&](size_t j) {
    const esdf::Vec3 xj = filter.mean(j);
    return std::hypot(xj(0) - tx, xj(1) - ty);
  };
  const auto& keyframes = map.keyframes();
  size_t best = earlier;
  double best_d = dist(earlier);
  for (int step : {-1, 1}) {
    size_t j = earlier;
    double last = dist(earlier);
    for (int n = 0; n < 400; ++n) {
      if ((step < 0 && j == 0) || (step > 0 && j >= newest_allowed)) break;
      j = step < 0 ? j - 1 : j + 1;
      const double d = dist(j);
      if (d > last + 1.0) break;  // moving away again (the path may waver by a metre)
      last = std::min(last, d);
      if (d < best_d && keyframes[j].hasScan()) {
        best = j;
        best_d = d;
      }
    }
  }
  if (best == earlier || best_d > options_.search_radius_m + 0.25 * options_.opposite_view_offset_m) return std::nullopt;
  return best;
}

alignment::AlignmentResult LoopCloser::verifyAlignment(const io::LaserScan& earlier_scan, const io::LaserScan& current_scan,
                                                       const common::Pose2& guess, alignment::Method method, double reach_m,
                                                       LoopClosureRecord& r, const alignment::PoseRegion* admitted) const {
  const AlignedScans a = alignScans(earlier_scan, current_scan, guess, method, reach_m, r, admitted);
  if (r.reason != ClosureReason::None) return a.result;
  if (ambiguous(a)) {
    r.reason = ClosureReason::Ambiguous;
    return a.result;
  }
  freeSpaceConflict(earlier_scan, current_scan, r);
  return a.result;
}

LoopCloser::AlignedScans LoopCloser::alignScans(const io::LaserScan& earlier_scan, const io::LaserScan& current_scan,
                                                const common::Pose2& guess, alignment::Method method, double reach_m, LoopClosureRecord& r,
                                                const alignment::PoseRegion* admitted) const {
  AlignedScans out;
  out.reach_m = reach_m;
  alignment::AlignerOptions& ao = out.options;
  ao.min_constraint_ratio = options_.min_constraint_ratio;
  ao.method = method;
  // ICP restarts from CRF-match's best two consensus hypotheses (and its transform and the guess),
  // not four: most far candidates fail, and each restart costs them ICP iterations. The other
  // two changed no accepted closure of the 1, 10 and 100 km² cities, Intel, FR079, CSAIL, the
  // campus, Victoria Park or UAL; on ACES 9 closures replaced 7 (220 against 218, relation error
  // 0.0369 m against 0.0370); the cities ran 3-6 % faster (bench/scale/RESULTS.md).
  ao.crf.hypotheses_kept = 2;
  alignment::PointSet earlier_set = alignment::pointSetFromScan(earlier_scan, ao.scan, ao.in_vehicle_frame);
  out.current = alignment::pointSetFromScan(current_scan, ao.scan, ao.in_vehicle_frame);
  // Two 180° scans that looked away from each other, or at places the other never saw, share no
  // points wherever the gate would put them: the check costs microseconds, a global alignment
  // that is bound to fail milliseconds (the most common failure in a city: the opposite lane).
  if (admitted) {
    alignment::ViewOverlapOptions vo;
    vo.gate_m = ao.icp.gate_final_m;
    const alignment::ViewSector sector = alignment::viewSector(earlier_set, earlier_scan.sensor_pose);
    if (!alignment::mayMatchShare(sector, out.current, *admitted, options_.min_matched_fraction, vo)) {
      r.measurement = guess;
      r.reason = ClosureReason::NoOverlap;
      return out;
    }
  }
  // The point sets, kd-tree and line normals built once for every alignment below (the
  // ambiguity test restarts PL-ICP up to 16 times).
  out.earlier = std::make_unique<const alignment::IndexedReference>(std::move(earlier_set));
  // Below min_matched_fraction an alignment is refused: its ICP runs (from CRF-match's
  // hypotheses and the guess) that cannot reach it are given up early. The ambiguity test's
  // restarts are given up the same way below the count that would make them another minimum
  // (`findsOtherMinimum`).
  alignment::AlignerOptions first = ao;
  first.icp.abandon_below_fraction = options_.min_matched_fraction;
  out.result = alignment::alignPointSets(*out.earlier, out.current, guess, first);
  const alignment::AlignmentResult& a = out.result;
  r.measurement = a.transform;
  r.rms_m = a.rms_residual_m;
  if (!a.converged || a.rms_residual_m > options_.max_rms_m || a.matchedFraction() < options_.min_matched_fraction)
    r.reason = ClosureReason::Alignment;
  return out;
}

bool LoopCloser::ambiguous(const AlignedScans& a) const {
  if (options_.ambiguity_offset_m <= 0) return false;
  // A wrong closure is usually a wrong local minimum (aliasing along a corridor or a facade) that
  // the drifted estimate happened to start PL-ICP in: restarts from the result shifted by
  // ambiguity_offset_m, twice, four and eight times that, as far as reach_m (for a closure, 3
  // sigma of the relative position: what the innovation gate could admit) must find no minimum
  // elsewhere that matches clearly more points.
  alignment::ShiftedRestarts restarts;
  restarts.first_shift_m = options_.ambiguity_offset_m;
  restarts.last_shift_m = std::min(8 * options_.ambiguity_offset_m, 2 * a.reach_m);
  restarts.same_minimum_m = 0.25 * options_.ambiguity_offset_m;
  restarts.min_match_ratio = 1.0 + options_.ambiguity_min_gain;
  restarts.max_rms_m = options_.max_rms_m;
  return alignment::findsOtherMinimum(*a.earlier, a.current, a.result, a.options, restarts);
}

bool LoopCloser::freeSpaceConflict(const io::LaserScan& earlier_scan, const io::LaserScan& current_scan, LoopClosureRecord& r) const {
  r.free_space_conflict = alignment::mutualFreeSpaceConflict(earlier_scan, current_scan, r.measurement, freeSpaceOptions(options_));
  if (r.free_space_conflict <= options_.max_free_space_conflict) return false;
  r.reason = ClosureReason::FreeSpace;
  return true;
}

io::LaserScan LoopCloser::staticScan(KeyframeNodes& filter, const Map& map, size_t k) {
  return moving_.scanWithout(map, k, map.size() - 1, [&](size_t j) { return esdf::toPose(filter.mean(j)); });
}

common::Pose2 carriedClosure(const Map& map, const LoopClosureRecord& c, size_t earlier, size_t current) {
  const auto& kf = map.keyframes();
  return common::compose(common::compose(common::between(kf[earlier].pose, kf[c.from].pose), c.measurement),
                         common::between(kf[c.to].pose, kf[current].pose));
}

bool LoopCloser::continuesClosure(const Map& map, const LoopClosureRecord& c, size_t earlier, size_t current,
                                  const common::Pose2& z) const {
  // Another visit's scans were never aligned with the current ones: the restarts are theirs to pass.
  if ((earlier > c.from ? earlier - c.from : c.from - earlier) >= static_cast<size_t>(options_.min_keyframe_gap)) return false;
  const common::Pose2 d = common::between(carriedClosure(map, c, earlier, current), z);
  return std::hypot(d.x, d.y) <= 0.25 * options_.ambiguity_offset_m && std::abs(d.phi) <= options_.confirm_tolerance_deg * M_PI / 180;
}

LoopClosureRecord LoopCloser::tryClose(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current, bool commit,
                                       const Detection* detection, const LoopClosureRecord* recent) {
  const auto& keyframes = map.keyframes();
  LoopClosureRecord r;
  r.from = earlier;
  r.to = current;
  r.from_time = keyframes[earlier].timestamp;
  r.to_time = keyframes[current].timestamp;
  r.detector = detection ? detection->detector : Proposer::Pose;
  if (detection) r.score = detection->score;
  // Alignment from the current estimate of the relative pose.
  const esdf::Vec3 xi = filter.mean(earlier), xk = filter.mean(current);
  const Eigen::Matrix3d s = relativeCovariance(filter, earlier, current);
  r.prior_sigma_m = esdf::largestPositionSigma(s);
  alignment::Method method = alignment::Method::CrfIcp;
  if (options_.method == LoopClosureOptions::Method::Auto) {
    // A well-known relative pose needs only the fast local refinement (PL-ICP); a poorly known
    // one the global coarse alignment first (CRF-match, then ICP), as in the thesis.
    const double sxy = std::sqrt(std::max(s(0, 0), s(1, 1))), sphi = std::sqrt(s(2, 2));
    method = 3 * sxy < options_.auto_local_max_m && 3 * sphi < options_.auto_local_max_deg * M_PI / 180 ? alignment::Method::PlIcp
                                                                                                        : alignment::Method::CrfIcp;
  } else {
    using M = LoopClosureOptions::Method;
    const M m = options_.method;
    method = m == M::Icp     ? alignment::Method::Icp
             : m == M::PlIcp ? alignment::Method::PlIcp
             : m == M::Crf   ? alignment::Method::Crf
                             : alignment::Method::CrfIcp;
  }
  // (Trying PL-ICP first on an uncertain guess was measured worse: it lands in wrong local
  // minima that pass the residual test — ATE 2.96 m vs 0.26 m on Intel.)
  // The map keeps its scans compact (and maybe on disk): expanded once for this candidate, the
  // returns of what moved hidden (the current keyframe's once for all its candidates).
  const io::LaserScan earlier_scan = staticScan(filter, map, earlier);
  if (current_scan_for_ != current || current_scan_map_ != &map || current_scan_judged_to_ != map.size()) {
    current_scan_ = staticScan(filter, map, current);
    current_scan_for_ = current;
    current_scan_map_ = &map;
    current_scan_judged_to_ = map.size();
  }
  const io::LaserScan& current_scan = current_scan_;
  const common::Pose2 guess = esdf::toPose(esdf::between(xi, xk));
  // Where the innovation gate admits a measurement: the relative pose's own uncertainty (the
  // alignment's, centimetres, is left out), at the filter's own quantile.
  const alignment::PoseRegion admitted{guess, s, filter.gateThreshold()};
  // The checks of verifyAlignment, with the ambiguity restarts (its costly part) left until the
  // measurement is final and the gate has not refused it already.
  const AlignedScans aligned =
      alignScans(earlier_scan, current_scan, guess, method, 3 * r.prior_sigma_m, r, options_.view_test ? &admitted : nullptr);
  const alignment::AlignmentResult& a = aligned.result;
  if (!detection) r.score = a.matchedFraction();
  if (r.reason != ClosureReason::None || freeSpaceConflict(earlier_scan, current_scan, r)) return r;
  // A closure far beyond what the estimate knew (found by appearance or from a wide prior) is
  // where a consistently aliased street gets in: the two visits' path submaps, aligned from it,
  // must have no other alignment nearly as good within the gate's reach, and their alignment
  // becomes the measurement (more of the street than two scans see; the two scans' covariance
  // is kept, the conservative of the two).
  // Two narrow views heading opposite ways meet only ahead of both (oppositeViewPartner), on a
  // stretch of street that slides along itself as easily as a far closure's: the same check.
  std::optional<PathSubmapAlignment> submaps;
  const bool far = r.prior_sigma_m > options_.appearance_min_sigma_m;
  if (options_.submap_check_path_m > 0 && (far || headingOtherWay(map, xi, xk, current))) {
    PathSubmapOptions po;
    po.path_m = options_.submap_check_path_m;
    submaps.emplace(map, earlier, current, a.transform, 3 * r.prior_sigma_m, po);
    if (submaps->aligned()) {
      // The submaps' measurement replaces the scans' only where the two scans agree on free space
      // there too: along a street of one repeated design (window bays metres apart) the submaps
      // can settle one period away from where the scans fitted without conflict.
      const double conflict =
          alignment::mutualFreeSpaceConflict(earlier_scan, current_scan, submaps->measurement(), freeSpaceOptions(options_));
      if (conflict <= options_.max_free_space_conflict) {
        r.measurement = submaps->measurement();
        r.free_space_conflict = conflict;
      }
    }
    // Far from the map, neighbourhoods that do not overlap where the closure puts them are two
    // places whose single scans look alike (a stretch of street like one 50 m along it, beyond
    // what the ambiguity restarts reach). Two narrow views heading opposite ways may see little
    // of each other's street: theirs are left to the other tests.
    if (far && submaps->disagree()) {
      r.reason = ClosureReason::Submaps;
      return r;
    }
  }
  const esdf::Mat3 cov = options_.covariance_scale * a.cov;
  r.information = cov.inverse();
  // A closure the gate refuses whatever the restarts say is refused before them, when that is
  // known without a factorisation (Esdf::refusalWithoutFactorising): far from the map most aligned
  // candidates are refused by the gate (the 1,000 km city drive after a long drift: 467 of the
  // 485 that reached it), and the restarts of the scans and of the submaps were most of their
  // cost. Every test's verdict is the same in either order; the reason given to a candidate that
  // fails several tests changes. With the joint gate, a refusal by less than two closures'
  // quantile still takes the tests: the closure may pass with a second one. (The early refusal's
  // d^2 is a lower bound of the exact one, so a pair beyond is beyond too.)
  const auto refused = filter.refusalWithoutFactorising(earlier, current, esdf::toVec(r.measurement), r.information);
  if (refused && (!options_.joint_gate || refused->mahalanobis2 > filter.jointGateThreshold())) {
    r.mahalanobis2 = refused->mahalanobis2;
    r.gate_threshold = refused->threshold;
    r.reason = ClosureReason::Gating;
    return r;
  }
  // Along a revisit every keyframe's closure would restart PL-ICP up to 16 times about a minimum
  // whose uniqueness the last accepted closure's restarts tested (a third of global SLAM's time
  // late in a 1,000 km city drive). Where this alignment continues that closure, they are left out.
  r.restarts_skipped = recent && continuesClosure(map, *recent, earlier, current, a.transform);
  if (!r.restarts_skipped && ambiguous(aligned)) {
    r.reason = ClosureReason::Ambiguous;
    return r;
  }
  if (submaps && submaps->ambiguous()) {
    r.reason = ClosureReason::Submaps;
    return r;
  }
  // Innovation gate, then the information-form update.
  esdf::GateResult gate;
  if (commit) {
    gate =
        filter.observeRelative(earlier, current, esdf::toVec(r.measurement), r.information, true).gate;
  } else {
    gate = filter.gateRelative(earlier, current, esdf::toVec(r.measurement), r.information);
  }
  r.mahalanobis2 = gate.mahalanobis2;
  r.gate_threshold = gate.threshold;
  r.accepted = gate.accepted;
  if (!r.accepted) r.reason = ClosureReason::Gating;
  return r;
}

LoopClosureRecord LoopCloser::tryCloseMeasured(KeyframeNodes& filter, const Map& map, size_t earlier, size_t current, const esdf::Vec3& z,
                                               const Eigen::Matrix3d& information, bool commit, const Detection& detection,
                                               const CameraMeasurement* camera) {
  const auto& keyframes = map.keyframes();
  LoopClosureRecord r;
  r.from = earlier;
  r.to = current;
  r.from_time = keyframes[earlier].timestamp;
  r.to_time = keyframes[current].timestamp;
  r.detector = detection.detector;
  r.score = detection.score;
  const Eigen::Matrix3d s = relativeCovariance(filter, earlier, current);
  r.prior_sigma_m = esdf::largestPositionSigma(s);
  r.measurement = esdf::toPose(z);
  r.bearing_only = camera && !camera->metric.valid;
  r.information = information;
  if (camera && nearestSceneDepth(*camera, filter.mean(earlier), filter.mean(current), s) >
                    options_.max_scene_depth_m) {
    r.reason = ClosureReason::SceneDepth;
    return r;
  }
  const esdf::GateResult gate =
      commit ? filter.observeRelative(earlier, current, z, information, true).gate
             : filter.gateRelative(earlier, current, z, information);
  r.mahalanobis2 = gate.mahalanobis2;
  r.gate_threshold = gate.threshold;
  r.accepted = gate.accepted;
  if (!r.accepted) r.reason = ClosureReason::Gating;
  return r;
}

}  // namespace urbanslam::slam
