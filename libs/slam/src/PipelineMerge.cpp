// Another session's map appended to this one and optimised jointly (Pipeline::appendSession).
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::slam {

void Pipeline::appendSession(const Pipeline& session, const SessionJoin& join) {
  if (finished_ || session.finished_) throw std::logic_error("Pipeline::appendSession after finish()");
  if (!map_.filter())
    throw common::InputError("maps built in dead reckoning cannot be merged: they have no filter to optimise them jointly");
  drainGlobalSlam();
  session.global_worker_.drain();
  const Map& other = session.map_;
  const size_t n0 = map_.size();
  if (other.empty()) return;
  // This map's last keyframes, still waiting for their search, are searched as at the end of
  // its input: the session's keyframes that follow them were not driven after them.
  global_.closePendingLoops(std::chrono::steady_clock::now());

  // This map's keyframe nearest to `p` within `radius_m` among its own (not the session's), with
  // a scan when `scan` says so; none: n0.
  const auto nearestOwn = [&](const common::Pose2& p, double radius_m, bool scan) {
    std::vector<size_t> near;
    map_.index().query(p.x, p.y, radius_m, near);
    size_t found = n0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i : near) {
      if (i >= n0 || (scan && !map_.keyframes()[i].hasScan())) continue;
      const double d = std::hypot(map_.keyframes()[i].pose.x - p.x, map_.keyframes()[i].pose.y - p.y);
      if (d < best) best = d, found = i;
    }
    return found;
  };

  // The session's odometry constraints, by the keyframe they lead to. A session that is itself
  // a merge (a map kept separate in a file, then linked) has its later sessions' first
  // keyframes hang from an earlier keyframe by their join: that constraint is kept as it is.
  std::vector<std::optional<GraphEdge>> chain(other.size());
  other.edges().forEach([&](const GraphEdge& e) {
    if (!e.loop_closure && e.from < e.to && e.to < chain.size() && (!chain[e.to] || e.from > chain[e.to]->from)) chain[e.to] = e;
  });

  // The session's first keyframe hangs from the map by the join's transform with the join's
  // drift allowance over the session's path to the anchor fix (tens of metres for a fix kilometres
  // into a drive), and the fixes tie the session down only when their keyframes are appended.
  // Before that, a closure of the session's keyframes with this map must put the keyframe where
  // one of the join's fixes does, as two fixes must agree to join (agreesWithJoin): a look-alike
  // place of the map inside the allowance would otherwise take the whole session there.
  size_t first_fix = other.size();
  for (size_t i : join.agreeing) first_fix = std::min(first_fix, join.fixes[i].keyframe);
  std::vector<double> path_m(other.size(), 0.0);
  for (size_t k = 1; k < other.size(); ++k) {
    const common::Pose2 &a = other.keyframes()[k - 1].pose, &b = other.keyframes()[k].pose;
    path_m[k] = path_m[k - 1] + std::hypot(b.x - a.x, b.y - a.y);
  }
  global_.setJoinCheck([&, n0, first_fix](const LoopClosureRecord& r) {
    if (r.from >= n0 || r.to < n0 || r.to >= n0 + first_fix) return false;
    const common::Pose2 claimed = common::compose(esdf::toPose(map_.nodes()->mean(r.from)), r.measurement);
    return !agreesWithJoin(join, r.to - n0, other.keyframes()[r.to - n0].pose, path_m, claimed);
  });
  // Cleared when this call returns or throws (a bad session): it refers to this call's locals, and
  // the closures it is for are all sought in the loop below.
  struct ClearedAtExit {
    GlobalSlam& global;
    ~ClearedAtExit() { global.setJoinCheck({}); }
  } cleared{global_};
  const auto now = std::chrono::steady_clock::now();
  for (const Keyframe& k : other.keyframes()) {
    KeyframeConstraint c;
    if (k.index == 0) {
      // The first keyframe hangs from this map's keyframe nearest to where the join puts it, by
      // the join's transform with its uncertainty; the closures that global SLAM finds next tie
      // the two maps together with their real weight.
      const common::Pose2 placed = common::compose(join.transform, k.pose);
      size_t from = nearestOwn(placed, 50.0, false);
      if (from == n0) from = n0 - 1;
      c.z = common::between(map_.keyframes()[from].pose, placed);
      c.cov = join.transform_cov;
      global_.addKeyframeFrom(from, Keyframe{n0, k.timestamp, {}, false, k.has_image, k.image_words}, io::CompactScan(other.scan(0)), c);
    } else {
      const std::optional<GraphEdge>& e = chain[k.index];
      if (!e)
        throw common::InputError("the session's keyframe " + std::to_string(k.index) + " has no odometry constraint from the one before");
      c.z = e->measurement;
      c.cov = e->information.inverse();
      Keyframe kf{n0 + k.index, k.timestamp, {}, false, k.has_image, k.image_words};
      if (e->from + 1 == k.index)
        global_.addKeyframe(std::move(kf), io::CompactScan(other.scan(k.index)), c);
      else
        global_.addKeyframeFrom(n0 + e->from, std::move(kf), io::CompactScan(other.scan(k.index)), c);
    }
    // The places the join recognised, tied to this map's keyframe nearest to each.
    for (size_t i : join.agreeing) {
      const SessionFix& f = join.fixes[i];
      if (f.keyframe != k.index) continue;
      const size_t earlier = nearestOwn(f.pose, 10.0, true);
      if (earlier < n0)
        global_.addPlaceFix(earlier, n0 + k.index, common::between(map_.keyframes()[earlier].pose, f.pose),
                            fixCovariance(f, join.options).inverse(), f.margin_per_point, f.detector);
    }
    // Loop closures as a run finds them: against this map and the session's earlier keyframes.
    global_.closeLoops(n0 + k.index, now);
  }
  map_.appendTrajectory(other, n0);
  session.reference_.forEach([&](const io::StampedPose& p) { reference_.push_back(p); });

  // Local SLAM continues the session: its state (motion, submap in its own frame) with the
  // keyframes counted in the merged map, and global SLAM's estimate of the submap it will take.
  common::BinaryWriter w;
  session.local_.writeState(w);
  common::BinaryReader r(w.bytes().data(), w.bytes().size(), "session state");
  local_.readState(r);
  local_.renumber(map_.size());
  submap_corrections_.take(std::numeric_limits<size_t>::max());
  keyframe_tickets_.clear();
  const size_t lag = static_cast<size_t>(std::max(0, options_.local.correction_lag_keyframes));
  const size_t n = map_.size();
  for (size_t j = std::max(n0, n > lag + 1 ? n - lag - 1 : 0); j < n; ++j) {
    SubmapEstimate e{j, {}};
    const size_t count = std::min(j + 1 - n0, static_cast<size_t>(std::max(1, options_.local.submap_keyframes)));
    for (size_t i = j + 1 - count; i <= j; ++i) e.poses.push_back(map_.keyframes()[i].pose);
    submap_corrections_.publish(std::move(e));
  }
  images_ = KeyframeImageAssigner(options_.loop_closure.image_max_offset_s);

  const PipelineStats& s = session.stats_;
  stats_.measurements += s.measurements;
  stats_.scans += s.scans;
  stats_.scans_used += s.scans_used;
  stats_.odometry += s.odometry;
  stats_.drive += s.drive;
  stats_.images += s.images;
  stats_.gps += s.gps;
  stats_.reference += s.reference;
  stats_.scan_matches_used += s.scan_matches_used;
  stats_.scan_matches_rejected += s.scan_matches_rejected;
  stats_.scans_anchored += s.scans_anchored;
  stats_.first_timestamp = std::min(stats_.first_timestamp, s.first_timestamp);
  stats_.last_timestamp = std::max(stats_.last_timestamp, s.last_timestamp);
  stats_.keyframes = map_.size();
}

}  // namespace urbanslam::slam
