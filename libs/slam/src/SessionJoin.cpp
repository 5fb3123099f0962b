#include "urbanslam/slam/SessionJoin.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/MapAreas.h"
#include "urbanslam/slam/PlaceRecognizer.h"

namespace urbanslam::slam {

namespace {

constexpr double kDeg = M_PI / 180.0;

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// Two places of one session keyframe agree as two fixes must: within agree_m plus agree_per_m
// times the session's path between the two (its drift there), and agree_deg.
bool agree(const SessionJoinOptions& o, const common::Pose2& a, const common::Pose2& b, double path_between_m) {
  return std::hypot(a.x - b.x, a.y - b.y) <= o.agree_m + o.agree_per_m * path_between_m &&
         std::abs(wrap(a.phi - b.phi)) <= o.agree_deg * kDeg;
}

}  // namespace

struct SessionJoiner::Search {
  Search(const Map& map, const PipelineOptions& mo)
      : map(map),
        localizer(localizerOptions(mo)),
        areas(map, localizer.areas),
        places(map, areas, localizer.places),
        loop_closure(mo.loop_closure),
        closer(mo.loop_closure) {}
  const Map& map;
  LocalizerOptions localizer;
  MapAreas areas;
  PlaceRecognizer places;
  LoopClosureOptions loop_closure;
  LoopCloser closer;
  // The classifier's features of the map's keyframes (ids = keyframe indices), computed at the
  // first probe that needs them.
  std::unique_ptr<laser_loop::LoopDetector> detector;
};

SessionJoiner::SessionJoiner(const Map& map, const PipelineOptions& map_options, SessionJoinOptions options)
    : search_(std::make_unique<Search>(map, map_options)), options_(options) {
  join_.reason = map.empty() ? "the map is empty" : "no scan of the session was recognised in the map";
}

SessionJoiner::~SessionJoiner() = default;

void SessionJoiner::extendPath(const Map& session) {
  const auto& kf = session.keyframes();
  for (size_t i = path_.size(); i < kf.size(); ++i)
    path_.push_back(i == 0 ? 0.0 : path_.back() + std::hypot(kf[i].pose.x - kf[i - 1].pose.x, kf[i].pose.y - kf[i - 1].pose.y));
}

void SessionJoiner::appearanceFixes(size_t k, const io::LaserScan& scan) {
  Search& s = *search_;
  const LoopClosureOptions& lc = s.loop_closure;
  const Map& map = s.map;
  if (!s.detector) {
    s.detector = std::make_unique<laser_loop::LoopDetector>(laser_loop::LoopDetector::fromFile(laserModelFor(lc, scan)));
    s.detector->reserve(map.size());
    for (size_t i = 0; i < map.size(); ++i) s.detector->addKeyframe(map.scan(i));
  }
  std::vector<float> scores;
  s.detector->screen(s.detector->features(scan), scores);
  const double threshold = s.detector->factor() + lc.laser_threshold;
  std::vector<std::pair<float, size_t>> detected;
  for (size_t i = 0; i < scores.size(); ++i)
    if (scores[i] >= threshold && map.keyframes()[i].hasScan()) detected.emplace_back(scores[i], i);
  std::sort(detected.begin(), detected.end(),
            [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  // The best detections, one per place: an aliased place cannot take every slot.
  std::vector<size_t> picked;
  for (const auto& [score, i] : detected) {
    if (static_cast<int>(picked.size()) == options_.appearance_candidates) break;
    const common::Pose2& p = map.keyframes()[i].pose;
    const bool same = std::any_of(picked.begin(), picked.end(), [&](size_t j) {
      return std::hypot(map.keyframes()[j].pose.x - p.x, map.keyframes()[j].pose.y - p.y) < lc.search_radius_m;
    });
    if (same) continue;
    picked.push_back(i);
    // No prior: CRF-match finds the transform from the scans' shapes alone, and the ambiguity
    // restarts reach as far as they go.
    LoopClosureRecord r;
    const alignment::AlignmentResult a =
        s.closer.verifyAlignment(map.scan(i), scan, common::Pose2{}, alignment::Method::CrfIcp, std::numeric_limits<double>::infinity(), r);
    if (r.reason != ClosureReason::None) continue;
    SessionFix f;
    f.keyframe = k;
    f.detector = Proposer::Laser;
    f.pose = common::compose(p, a.transform);
    f.cov = lc.covariance_scale * a.cov;  // as a loop closure weighs an alignment
    f.margin_per_point = score - threshold;
    join_.fixes.push_back(f);
  }
}

bool SessionJoiner::probe(const Map& session, size_t k) {
  ++join_.probes;
  const size_t first = join_.fixes.size();
  const io::LaserScan scan = session.scan(k);
  // The exhaustive search where it is affordable: its time grows faster than the map (0.07 s in
  // a building's map of 60-85 windows, 4-9 s in a 3 km city drive's of 1200). Beyond
  // place_search_max_windows the classifier proposes instead: its screening of every keyframe is
  // one streaming pass. (Where the place search runs, the classifier's detections aligned from
  // no prior are the weaker fixes: on ACES they added one 1.6 m off that the agreement
  // tolerance let in, and the merge's relation error grew by a quarter.)
  if (search_->places.candidates() > static_cast<size_t>(options_.place_search_max_windows)) {
    if (options_.appearance_candidates > 0 && search_->loop_closure.detector == LoopClosureOptions::Detector::Laser)
      appearanceFixes(k, scan);
    return addFixes(session, first);
  }
  const PlaceHypothesis h = search_->places.locate(alignment::pointSetFromScan(scan, search_->areas.options().scan_model, true),
                                                   search_->areas.options().matcher);
  if (h.found) {
    SessionFix f;
    f.keyframe = k;
    f.pose = h.pose;
    // As the localizer takes a match: scaled for the correlated errors of matches against the
    // same map points, with floors for the map's own disagreements.
    f.cov = withFloors(search_->localizer.covariance_scale * h.cov, search_->localizer);
    f.margin_per_point = h.margin_per_point;
    join_.fixes.push_back(f);
  }
  return addFixes(session, first);
}

bool SessionJoiner::addFixes(const Map& session, size_t first) {
  if (join_.fixes.size() == first) return false;
  for (size_t i = first; i < join_.fixes.size(); ++i) check(session, join_.fixes[i]);
  decide(session);
  return join_.joined;
}

size_t SessionJoiner::check(const Map& session, SessionFix& f) {
  const Search& s = *search_;
  const Map& map = s.map;
  const auto& kf = session.keyframes();
  const SessionJoinOptions& o = options_;
  const common::Pose2 transform = common::compose(f.pose, common::inverse(kf[f.keyframe].pose));
  const double s0 = path_[f.keyframe];
  std::vector<size_t> near;
  const auto checkOne = [&](size_t j) {
    const common::Pose2 predicted = common::compose(transform, kf[j].pose);
    // The map's keyframe nearest to the prediction that sees the same side.
    near.clear();
    map.index().query(predicted.x, predicted.y, s.loop_closure.search_radius_m, near);
    size_t found = map.size();
    double best = std::numeric_limits<double>::infinity();
    for (size_t i : near) {
      const Keyframe& m = map.keyframes()[i];
      const double d = std::hypot(m.pose.x - predicted.x, m.pose.y - predicted.y);
      if (m.hasScan() && std::abs(wrap(m.pose.phi - predicted.phi)) <= o.check_max_deg * kDeg && d < best) best = d, found = i;
    }
    if (found == map.size()) return;  // the map has not seen this place: it tells nothing
    const double tolerance = o.agree_m + o.agree_per_m * std::abs(path_[j] - s0);
    const common::Pose2& m = map.keyframes()[found].pose;
    LoopClosureRecord r;
    const alignment::AlignmentResult a =
        s.closer.verifyAlignment(map.scan(found), session.scan(j), common::between(m, predicted), alignment::Method::PlIcp, tolerance, r);
    // A scan that does not align with the map's there tells little (another viewpoint within a
    // few metres sees other things indoors; a corridor is ambiguous along itself). One that
    // aligns elsewhere, or whose points stand where the map's beams passed through, contradicts.
    if (r.reason == ClosureReason::Alignment || r.reason == ClosureReason::Ambiguous) {
      f.unaligned.push_back(j);
      return;
    }
    const common::Pose2 landed = common::compose(m, a.transform);
    const bool lands = r.reason == ClosureReason::None && agree(o, landed, predicted, std::abs(path_[j] - s0));
    (lands ? f.confirmed : f.contradicted).push_back(j);
  };
  const size_t before = f.confirmed.size() + f.contradicted.size() + f.unaligned.size();
  const auto made = [&] { return f.confirmed.size() + f.contradicted.size() + f.unaligned.size() - before; };
  // The later scans as far as the session goes: a growing session's come in later calls, so the
  // checks of a fix found early go on as the session grows (checked_to, next_check_m).
  if (!f.checked_back) f.checked_to = f.keyframe, f.next_check_m = s0 + o.check_spacing_m;
  for (size_t j = f.checked_to + 1; j < kf.size() && path_[j] - s0 <= o.check_reach_m; ++j) {
    f.checked_to = j;
    if (kf[j].hasScan() && path_[j] >= f.next_check_m) checkOne(j), f.next_check_m = path_[j] + o.check_spacing_m;
  }
  if (f.checked_back) return made();
  f.checked_back = true;
  double next = s0 - o.check_spacing_m;
  for (size_t j = f.keyframe; j-- > 0 && s0 - path_[j] <= o.check_reach_m;)
    if (kf[j].hasScan() && path_[j] <= next) checkOne(j), next = path_[j] - o.check_spacing_m;
  return made();
}

const SessionJoin& SessionJoiner::update(const Map& session, const std::function<void(double)>& progress) {
  if (join_.joined) return join_;
  const auto& kf = session.keyframes();
  extendPath(session);
  // The fixes found so far, checked on the scans that came since.
  size_t checks = 0;
  for (SessionFix& f : join_.fixes) checks += check(session, f);
  if (checks > 0) decide(session);
  // The session's scans searched for in the whole map, one every probe_spacing_m of its path,
  // until the join is found.
  for (; seen_ < kf.size() && !join_.joined; ++seen_) {
    if (progress) progress(static_cast<double>(seen_) / static_cast<double>(kf.size()));
    if (!kf[seen_].hasScan() || path_[seen_] < next_probe_m_) continue;
    next_probe_m_ = path_[seen_] + options_.probe_spacing_m;
    probe(session, seen_);
  }
  return join_;
}

const SessionJoin& SessionJoiner::searchAll(const Map& session, const std::function<void(double)>& progress) {
  const auto& kf = session.keyframes();
  extendPath(session);
  std::vector<size_t> probes;
  for (; seen_ < kf.size(); ++seen_) {
    if (!kf[seen_].hasScan() || path_[seen_] < next_probe_m_) continue;
    next_probe_m_ = path_[seen_] + options_.probe_spacing_m;
    probes.push_back(seen_);
  }
  // Coarse to fine (the probes in bit-reversed order: the whole path at a wide spacing first,
  // then the gaps halved): a session that shares much of its path with the map is joined after a
  // few searches instead of one every probe_spacing_m along it.
  size_t bits = 0;
  while ((size_t{1} << bits) < probes.size()) ++bits;
  size_t done = 0;
  for (size_t i = 0; i < (size_t{1} << bits) && !join_.joined; ++i) {
    size_t r = 0;
    for (size_t b = 0; b < bits; ++b) r |= ((i >> b) & 1u) << (bits - 1 - b);
    if (r >= probes.size()) continue;
    if (progress) progress(static_cast<double>(done++) / static_cast<double>(probes.size()));
    probe(session, probes[r]);
  }
  return join_;
}

void SessionJoiner::decide(const Map& session) {
  const SessionJoinOptions& o = options_;
  const auto& kf = session.keyframes();
  SessionJoin& out = join_;
  // 2. Agreement: fix a's transform carries fix b's keyframe to where b was found. (The
  // session's poses as they are now: a growing session's may have moved since the fix.)
  const auto agreeing_fixes = [&](const SessionFix& a, const SessionFix& b) {
    return agree(o, common::compose(a.transform, kf[b.keyframe].pose), b.pose, std::abs(path_[a.keyframe] - path_[b.keyframe]));
  };
  for (SessionFix& f : out.fixes) f.transform = common::compose(f.pose, common::inverse(kf[f.keyframe].pose));
  const size_t n = out.fixes.size();
  std::vector<std::vector<size_t>> agreeing(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      if (i == j || agreeing_fixes(out.fixes[i], out.fixes[j])) agreeing[i].push_back(j);
  std::set<size_t> with_fix;
  for (const SessionFix& f : out.fixes) with_fix.insert(f.keyframe);

  // A set of fixes is judged by the session's scans that support it and those against it, in
  // two ways; either joins.
  //  - Agreement: its fixes' own scans; against, the scans whose fixes all lie elsewhere.
  //  - Confirmation: its fixes' scans and their confirmations (one scan can give a fix at each
  //    of several look-alike places); against, the checks that contradicted it and no fix of
  //    the set confirmed. One of its fixes must have min_confirmations.
  struct Tally {
    std::set<size_t> support, against;
  };
  const auto agreement = [&](const std::vector<size_t>& fixes) {
    Tally t;
    for (size_t j : fixes) t.support.insert(out.fixes[j].keyframe);
    for (size_t k : with_fix)
      if (!t.support.count(k)) t.against.insert(k);
    return t;
  };
  const auto confirmation = [&](const std::vector<size_t>& fixes) {
    Tally t;
    for (size_t j : fixes) {
      t.support.insert(out.fixes[j].keyframe);
      t.support.insert(out.fixes[j].confirmed.begin(), out.fixes[j].confirmed.end());
    }
    for (size_t j : fixes)
      for (size_t k : out.fixes[j].contradicted)
        if (!t.support.count(k)) t.against.insert(k);
    return t;
  };
  struct Verdict {
    size_t best = 0;
    Tally tally;
    size_t rival = 0;
    bool joined = false;
    std::string reason;
  };
  // A fix most of whose checks landed where it puts them, min_confirmations at least.
  const auto confirmedFix = [&](size_t j) {
    const SessionFix& f = out.fixes[j];
    const size_t yes = f.confirmed.size(), tried = yes + f.contradicted.size() + f.unaligned.size();
    return static_cast<int>(yes) >= o.min_confirmations && static_cast<double>(yes) >= o.min_agreeing_share * static_cast<double>(tried);
  };
  const auto judge = [&](const auto& count, bool need_confirmed) {
    Verdict v;
    std::vector<size_t> supported(n);
    for (size_t i = 0; i < n; ++i) supported[i] = count(agreeing[i]).support.size();
    // The best set: by confirmation, one around a confirmed fix if there is one (wrong fixes
    // that agree loosely can gather more scans while the right one is young); the most scans,
    // then the clearer fix.
    const auto eligible = [&](size_t i) { return !need_confirmed || confirmedFix(i); };
    const auto better = [&](size_t i, size_t b) {
      if (eligible(i) != eligible(b)) return eligible(i);
      return supported[i] > supported[b] || (supported[i] == supported[b] && out.fixes[i].margin_per_point > out.fixes[b].margin_per_point);
    };
    for (size_t i = 1; i < n; ++i)
      if (better(i, v.best)) v.best = i;
    const std::vector<size_t>& set = agreeing[v.best];
    v.tally = count(set);
    // The largest set among the fixes that disagree with the best one (by confirmation, only
    // sets around a confirmed fix rival it: look-alike streets give unconfirmed ones anywhere).
    const auto inBest = [&](size_t i) { return std::find(set.begin(), set.end(), i) != set.end(); };
    for (size_t i = 0; i < n; ++i) {
      if (inBest(i) || !eligible(i)) continue;
      std::vector<size_t> outside;
      for (size_t j : agreeing[i])
        if (!inBest(j)) outside.push_back(j);
      v.rival = std::max(v.rival, count(outside).support.size());
    }
    const bool confirmed = eligible(v.best) && std::any_of(set.begin(), set.end(), confirmedFix);
    const size_t m = v.tally.support.size(), checked = m + v.tally.against.size();
    const double span = path_[*v.tally.support.rbegin()] - path_[*v.tally.support.begin()];
    if (static_cast<int>(m) < o.min_agreeing)
      v.reason = std::to_string(m) + " scans support the best fix (at least " + std::to_string(o.min_agreeing) + " needed)";
    else if (span < o.min_span_m)
      v.reason = "the scans supporting the best fix span " + std::to_string(span) + " m of the session's path";
    else if (need_confirmed && !confirmed)
      v.reason = "no fix of the best set has " + std::to_string(o.min_confirmations) +
                 " of the session's scans landing where it puts them, and most of those checked";
    else if (static_cast<double>(m) < o.min_agreeing_share * static_cast<double>(checked))
      v.reason = std::to_string(m) + " of " + std::to_string(checked) + " scans support the best fix";
    else if (static_cast<int>(v.rival) >= o.min_agreeing)
      v.reason = "ambiguous: " + std::to_string(v.rival) + " scans support another place";
    else
      v.joined = true;
    return v;
  };
  const Verdict by_agreement = judge(agreement, false);
  const Verdict v = by_agreement.joined ? by_agreement : judge(confirmation, true);
  out.agreeing = agreeing[v.best];
  out.agreeing_scans = v.tally.support.size();
  out.contradicting_scans = v.tally.against.size();
  out.rival = v.rival;
  out.joined = v.joined;
  out.reason = v.reason;
  // The transform of the agreeing fix nearest to the session's start along its path: the one
  // least affected by the session's drift there, where the session will hang from the map.
  size_t anchor = v.best;
  for (size_t j : out.agreeing)
    if (path_[out.fixes[j].keyframe] < path_[out.fixes[anchor].keyframe]) anchor = j;
  out.transform = out.fixes[anchor].transform;
  out.options = o;
  const double sxy = o.agree_m + o.agree_per_m * path_[out.fixes[anchor].keyframe], sphi = o.agree_deg * kDeg;
  out.transform_cov = Eigen::Vector3d(sxy * sxy, sxy * sxy, sphi * sphi).asDiagonal();
}

Eigen::Matrix3d fixCovariance(const SessionFix& fix, const SessionJoinOptions& options) {
  if (fix.detector != Proposer::Place) return fix.cov;
  return esdf::withDiagonalFloors(fix.cov, options.agree_m, options.agree_deg * kDeg);
}

bool agreesWithJoin(const SessionJoin& join, size_t keyframe, const common::Pose2& pose, const std::vector<double>& path_m,
                    const common::Pose2& claimed) {
  return std::any_of(join.agreeing.begin(), join.agreeing.end(), [&](size_t i) {
    const SessionFix& f = join.fixes[i];
    return agree(join.options, claimed, common::compose(f.transform, pose), std::abs(path_m.at(keyframe) - path_m.at(f.keyframe)));
  });
}

SessionJoin findSessionJoin(const Map& map, const PipelineOptions& map_options, const Map& session, const SessionJoinOptions& options,
                            const std::function<void(double)>& progress) {
  SessionJoiner joiner(map, map_options, options);
  return joiner.searchAll(session, progress);
}

}  // namespace urbanslam::slam
