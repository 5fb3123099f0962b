#include "urbanslam/slam/Map.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/KeyframeNodes.h"

namespace urbanslam::slam {

namespace {
constexpr size_t kNone = std::numeric_limits<size_t>::max();
}  // namespace

Map::Map(std::unique_ptr<esdf::Esdf> filter, double index_cell_m, size_t scan_cache_bytes, std::string spill_dir, bool reduced_pose_graph,
         size_t own_poses_first)
    : scans_(scan_cache_bytes, spill_dir),
      edges_("pose graph edges", spill_dir),
      index_(index_cell_m),
      filter_(std::move(filter)),
      nodes_(filter_ ? std::make_unique<KeyframeNodes>(*filter_, reduced_pose_graph, own_poses_first) : nullptr),
      odometry_("odometry readings", spill_dir) {}

Map::~Map() = default;

void Map::addKeyframe(Keyframe kf, io::CompactScan scan) {
  if (kf.index != keyframes_.size())
    throw std::logic_error("Map::addKeyframe: keyframe " + std::to_string(kf.index) + " added as keyframe " +
                           std::to_string(keyframes_.size()));
  kf.has_scan = !scan.empty();
  scans_.add(std::move(scan));
  index_.insert(kf.index, kf.pose.x, kf.pose.y);
  keyframes_.push_back(std::move(kf));
}

void Map::reindex() {
  index_.clear();
  for (const auto& k : keyframes_) index_.insert(k.index, k.pose.x, k.pose.y);
}

void Map::pullPoses(size_t from) {
  for (size_t i = from; i < keyframes_.size(); ++i) keyframes_[i].pose = esdf::toPose(nodes_->mean(i));
}

void Map::addAnchor(const ScanAnchor& anchor) {
  anchors_.push_back(anchor);
  // Odometry readings taken at the scan's time hang from it: the trajectory at that time is the
  // scan's pose, not the odometry prediction from the anchor before.
  odometry_.amendNewest([&](OdometrySample& s) {
    if (s.timestamp != anchor.timestamp) return false;
    s.anchor = anchors_.size() - 1;
    return true;
  });
}

void Map::addOdometry(double timestamp, const common::Pose2& odom) {
  odometry_.push_back({timestamp, odom, anchors_.empty() ? kNone : anchors_.size() - 1});
}

void Map::appendTrajectory(const Map& other, size_t keyframe_offset) {
  const size_t anchor_offset = anchors_.size();
  for (ScanAnchor a : other.anchors_) {
    a.keyframe += keyframe_offset;
    anchors_.push_back(a);
  }
  // A reading before the other map's first anchor hangs from that anchor, not from this map's.
  other.odometry_.forEach([&](OdometrySample s) {
    s.anchor = s.anchor == kNone ? anchor_offset : s.anchor + anchor_offset;
    odometry_.push_back(s);
  });
}

std::vector<io::StampedPose> Map::odometryTrajectory() const {
  std::vector<io::StampedPose> out;
  out.reserve(odometry_.size());
  const auto anchorPose = [&](const ScanAnchor& a) { return common::compose(keyframes_[a.keyframe].pose, a.offset); };
  const auto via = [&](size_t i, const common::Pose2& odom) {
    return common::compose(anchorPose(anchors_[i]), common::between(anchors_[i].odom, odom));
  };
  if (!anchors_.empty())
    odometry_.forEach([&](const OdometrySample& s) {
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
    });
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

std::vector<io::StampedPose> Map::scanTrajectory() const {
  std::vector<io::StampedPose> out;
  out.reserve(anchors_.size());
  for (const auto& a : anchors_) out.push_back({a.timestamp, common::compose(keyframes_[a.keyframe].pose, a.offset)});
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  return out;
}

std::vector<io::PosedScan> Map::posedKeyframes() const {
  std::vector<io::PosedScan> out;
  out.reserve(keyframes_.size());
  for (const auto& k : keyframes_) out.push_back({k.pose, nullptr, nullptr, &scans_, k.index});
  return out;
}

}  // namespace urbanslam::slam
