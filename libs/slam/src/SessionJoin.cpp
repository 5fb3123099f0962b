#include "urbanslam/slam/SessionJoin.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/MapAreas.h"
#include "urbanslam/slam/PlaceRecognizer.h"

namespace urbanslam::slam {

namespace {

constexpr double kDeg = M_PI / 180.0;

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

struct SessionJoiner::Search {
  Search(const Map& map, const LocalizerOptions& lo) : localizer(lo), areas(map, lo.areas), places(map, areas, lo.places) {}
  LocalizerOptions localizer;
  MapAreas areas;
  PlaceRecognizer places;
};

SessionJoiner::SessionJoiner(const Map& map, const PipelineOptions& map_options, SessionJoinOptions options)
    : search_(std::make_unique<Search>(map, localizerOptions(map_options))), options_(options) {
  join_.reason = map.empty() ? "the map is empty" : "no scan of the session was recognised in the map";
}

SessionJoiner::~SessionJoiner() = default;

void SessionJoiner::extendPath(const Map& session) {
  const auto& kf = session.keyframes();
  for (size_t i = path_.size(); i < kf.size(); ++i)
    path_.push_back(i == 0 ? 0.0 : path_.back() + std::hypot(kf[i].pose.x - kf[i - 1].pose.x, kf[i].pose.y - kf[i - 1].pose.y));
}

bool SessionJoiner::probe(const Map& session, size_t k) {
  ++join_.probes;
  const alignment::PointSet points = alignment::pointSetFromScan(session.scan(k), search_->areas.options().scan_model, true);
  const PlaceHypothesis h = search_->places.locate(points, search_->areas.options().matcher);
  if (!h.found) return false;
  SessionFix f;
  f.keyframe = k;
  f.pose = h.pose;
  // As the localizer takes a match (LocalizerOptions): scaled for the correlated errors of
  // matches against the same map points, with floors for the map's own disagreements.
  const LocalizerOptions& lo = search_->localizer;
  f.cov = lo.covariance_scale * h.cov;
  const double sxy = lo.min_sigma_xy_m, sphi = lo.min_sigma_deg * kDeg;
  f.cov(0, 0) = std::max(f.cov(0, 0), sxy * sxy);
  f.cov(1, 1) = std::max(f.cov(1, 1), sxy * sxy);
  f.cov(2, 2) = std::max(f.cov(2, 2), sphi * sphi);
  f.margin_per_point = h.margin_per_point;
  join_.fixes.push_back(f);
  decide(session);
  return join_.joined;
}

const SessionJoin& SessionJoiner::update(const Map& session, const std::function<void(double)>& progress) {
  const auto& kf = session.keyframes();
  extendPath(session);
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
  const auto agree = [&](const SessionFix& a, const SessionFix& b) {
    const common::Pose2 predicted = common::compose(a.transform, kf[b.keyframe].pose);
    const double drift = o.agree_per_m * std::abs(path_[a.keyframe] - path_[b.keyframe]);
    return std::hypot(predicted.x - b.pose.x, predicted.y - b.pose.y) <= o.agree_m + drift &&
           std::abs(wrap(predicted.phi - b.pose.phi)) <= o.agree_deg * kDeg;
  };
  for (SessionFix& f : out.fixes) f.transform = common::compose(f.pose, common::inverse(kf[f.keyframe].pose));
  const size_t n = out.fixes.size();
  std::vector<std::vector<size_t>> support(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      if (i == j || agree(out.fixes[i], out.fixes[j])) support[i].push_back(j);
  // The best set: the most supporters, then the clearer fix.
  size_t best = 0;
  for (size_t i = 1; i < n; ++i)
    if (support[i].size() > support[best].size() ||
        (support[i].size() == support[best].size() && out.fixes[i].margin_per_point > out.fixes[best].margin_per_point))
      best = i;
  out.agreeing = support[best];
  // The transform of the agreeing fix nearest to the session's start along its path: the one
  // least affected by the session's drift there, where the session will hang from the map.
  size_t anchor = best;
  for (size_t j : out.agreeing)
    if (path_[out.fixes[j].keyframe] < path_[out.fixes[anchor].keyframe]) anchor = j;
  out.transform = out.fixes[anchor].transform;
  const double sxy = o.agree_m + o.agree_per_m * path_[out.fixes[anchor].keyframe], sphi = o.agree_deg * kDeg;
  out.transform_cov = Eigen::Vector3d(sxy * sxy, sxy * sxy, sphi * sphi).asDiagonal();
  // The largest set among the fixes that disagree with the best one.
  const auto inBest = [&](size_t i) { return std::find(out.agreeing.begin(), out.agreeing.end(), i) != out.agreeing.end(); };
  out.rival = 0;
  for (size_t i = 0; i < n; ++i) {
    if (inBest(i)) continue;
    size_t outside = 0;
    for (size_t j : support[i]) outside += inBest(j) ? 0 : 1;
    out.rival = std::max(out.rival, outside);
  }

  // 3. Acceptance.
  double lo_s = path_[out.fixes[out.agreeing.front()].keyframe], hi_s = lo_s;
  for (size_t j : out.agreeing) {
    lo_s = std::min(lo_s, path_[out.fixes[j].keyframe]);
    hi_s = std::max(hi_s, path_[out.fixes[j].keyframe]);
  }
  const size_t m = out.agreeing.size();
  out.joined = false;
  if (static_cast<int>(m) < o.min_agreeing)
    out.reason =
        std::to_string(m) + " agreeing fixes of " + std::to_string(n) + " (at least " + std::to_string(o.min_agreeing) + " needed)";
  else if (hi_s - lo_s < o.min_span_m)
    out.reason = "the agreeing fixes span " + std::to_string(hi_s - lo_s) + " m of the session's path";
  else if (static_cast<double>(m) < o.min_agreeing_share * static_cast<double>(n))
    out.reason = std::to_string(m) + " of " + std::to_string(n) + " fixes agree";
  else if (static_cast<int>(out.rival) >= o.min_agreeing)
    out.reason = "ambiguous: " + std::to_string(out.rival) + " fixes agree on another place";
  else {
    out.joined = true;
    out.reason.clear();
  }
}

SessionJoin findSessionJoin(const Map& map, const PipelineOptions& map_options, const Map& session, const SessionJoinOptions& options,
                            const std::function<void(double)>& progress) {
  SessionJoiner joiner(map, map_options, options);
  return joiner.searchAll(session, progress);
}

}  // namespace urbanslam::slam
