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
  Search(const Map& map, const LocalizerOptions& lo) : areas(map, lo.areas), places(map, areas, lo.places) {}
  MapAreas areas;
  PlaceRecognizer places;
};

SessionJoiner::SessionJoiner(const Map& map, const PipelineOptions& map_options, SessionJoinOptions options)
    : search_(std::make_unique<Search>(map, localizerOptions(map_options))), options_(options) {
  join_.reason = map.empty() ? "the map is empty" : "no scan of the session was recognised in the map";
}

SessionJoiner::~SessionJoiner() = default;

const SessionJoin& SessionJoiner::update(const Map& session, const std::function<void(double)>& progress) {
  const auto& kf = session.keyframes();
  bool new_fix = false;
  // 1. Fixes: the session's scans searched for in the whole map, one every probe_spacing_m.
  for (; seen_ < kf.size(); ++seen_) {
    if (progress) progress(static_cast<double>(seen_) / static_cast<double>(kf.size()));
    const Keyframe& k = kf[seen_];
    path_.push_back(seen_ == 0 ? 0.0 : path_.back() + std::hypot(k.pose.x - kf[seen_ - 1].pose.x, k.pose.y - kf[seen_ - 1].pose.y));
    if (!k.hasScan() || path_.back() < next_probe_m_) continue;
    next_probe_m_ = path_.back() + options_.probe_spacing_m;
    ++join_.probes;
    const alignment::PointSet points = alignment::pointSetFromScan(session.scan(k.index), search_->areas.options().scan_model, true);
    const PlaceHypothesis h = search_->places.locate(points, search_->areas.options().matcher);
    if (!h.found) continue;
    SessionFix f;
    f.keyframe = k.index;
    f.pose = h.pose;
    f.cov = h.cov;
    f.margin_per_point = h.margin_per_point;
    f.transform = common::compose(h.pose, common::inverse(k.pose));
    join_.fixes.push_back(f);
    new_fix = true;
  }
  if (new_fix) decide(session);
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
  out.transform = out.fixes[best].transform;
  const double sxy = o.agree_m + o.agree_per_m * path_[out.fixes[best].keyframe], sphi = o.agree_deg * kDeg;
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
  return joiner.update(session, progress);
}

}  // namespace urbanslam::slam
