#pragma once
// The map: what a run builds and what outlives it. The keyframes (each with its scan and image
// words) and their current pose estimates, the pose graph's edges, the spatial index over the
// keyframes, the filter's information form (the ESDF; none in dead reckoning), and the scans
// and odometry readings hung from keyframes, from which the trajectory at every sensor time is
// rebuilt on demand. Local and global SLAM read it; only global SLAM changes the filter.
//
// The keyframes' own scans live in a scan store (io::ScanStore): compact, in memory up to a
// bound and in a spill file beyond it, so a city of a million keyframes does not hold them all.
// The pose graph's edges and the odometry readings, read only for the outputs, wait in spill
// files too.
#include <Eigen/Core>
#include <deque>
#include <memory>
#include <vector>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/io/CompactScan.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/ScanStore.h"
#include "urbanslam/io/SpillLog.h"
#include "urbanslam/slam/KeyframeGrid.h"
#include "urbanslam/vision_loop/BagOfWords.h"

namespace urbanslam::esdf {
class Esdf;
}

namespace urbanslam::slam {

class KeyframeNodes;

// What the map appends to per keyframe, up to millions of entries: a deque grows by fixed blocks,
// where a vector's doubling leaves up to half its capacity unused and, while it moves to a new
// buffer, holds three times its size at once.
template <class T>
using PerKeyframe = std::deque<T>;

struct Keyframe {
  size_t index = 0;
  double timestamp = 0;
  common::Pose2 pose;  // current estimate
  // Its scan is in the map's scan store (Map::scan); none for keyframes made from camera
  // images alone.
  bool has_scan = false;
  bool has_image = false;               // an image was attached (nearest in time)
  vision_loop::BagOfWords image_words;  // its Tree of Words vector (tree_of_words only); no pixels
  bool hasScan() const { return has_scan; }
};

// A constraint between two keyframes as it went into the filter (for the g2o output).
struct GraphEdge {
  size_t from = 0, to = 0;
  common::Pose2 measurement;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
  bool loop_closure = false;
};
// As the map file holds it, for the edges' spill file. PipelineState.cpp.
struct GraphEdgeCodec {
  static void write(common::BinaryWriter& w, const GraphEdge& e);
  static GraphEdge read(common::BinaryReader& r);
};
// One or two per keyframe, read only for the outputs and a merge: all but the newest wait in a
// spill file.
using GraphEdgeLog = io::SpillLog<GraphEdge, GraphEdgeCodec>;

// A scan whose pose is known relative to a keyframe: every keyframe (offset identity) and the
// scans between keyframes that matched the local submap. The trajectory between keyframes is
// spread between anchors, so it follows the scans rather than the odometry alone.
struct ScanAnchor {
  double timestamp = 0;
  size_t keyframe = 0;   // the keyframe it hangs from
  common::Pose2 offset;  // its pose in that keyframe's frame
  common::Pose2 odom;    // odometry pose at its time
};

class Map {
 public:
  // `filter`: the estimator behind the poses (nullptr: dead reckoning, poses composed from the
  // constraints). `index_cell_m`: the spatial index's cell. `scan_cache_bytes`, `spill_dir`: the
  // scan store's memory bound and spill folder (io::ScanStore). `reduced_pose_graph`: keyframes
  // may hang from the filter poses of others once `own_poses_first` are in (KeyframeNodes.h).
  Map(std::unique_ptr<esdf::Esdf> filter, double index_cell_m, size_t scan_cache_bytes = io::ScanStore::kDefaultCacheBytes,
      std::string spill_dir = {}, bool reduced_pose_graph = false, size_t own_poses_first = 0);
  ~Map();

  const PerKeyframe<Keyframe>& keyframes() const { return keyframes_; }
  size_t size() const { return keyframes_.size(); }
  bool empty() const { return keyframes_.empty(); }
  const Keyframe& back() const { return keyframes_.back(); }
  Keyframe& keyframe(size_t i) { return keyframes_[i]; }
  // `kf.index` must be size(); `scan` is its scan (empty: none), kept to the millimetre.
  void addKeyframe(Keyframe kf, io::CompactScan scan);

  // Keyframe k's scan (empty for a keyframe without one), read back from the spill file when
  // it is not in memory.
  io::LaserScan scan(size_t k) const { return scans_.expand(k); }
  void scanInto(size_t k, io::LaserScan& out) const { scans_.expandInto(k, out); }
  const io::ScanStore& scans() const { return scans_; }

  const GraphEdgeLog& edges() const { return edges_; }
  void addEdge(const GraphEdge& e) { edges_.push_back(e); }

  // Spatial index over the keyframes' current positions.
  const KeyframeGrid& index() const { return index_; }
  void reindex();

  esdf::Esdf* filter() { return filter_.get(); }
  const esdf::Esdf* filter() const { return filter_.get(); }
  // Which filter pose each keyframe is, and the filter read and updated by keyframe (nullptr
  // without a filter).
  KeyframeNodes* nodes() { return nodes_.get(); }
  const KeyframeNodes* nodes() const { return nodes_.get(); }
  // Copies the filter's current estimates of keyframes [from, size()) into their poses.
  void pullPoses(size_t from = 0);

  // The trajectory at sensor times.
  void addAnchor(const ScanAnchor& anchor);
  void addOdometry(double timestamp, const common::Pose2& odom);
  // The trajectory of another map whose keyframes were appended to this one from index
  // `keyframe_offset` on: its scan anchors and odometry samples.
  void appendTrajectory(const Map& other, size_t keyframe_offset);
  // Estimated pose at every odometry (or drive) reading's time and at every anchored scan (at a
  // scan's time this is the scan's pose), from the current keyframe estimates and the odometry
  // between the scans.
  std::vector<io::StampedPose> odometryTrajectory() const;
  // Estimated pose at every anchored scan: the keyframes and the scans matched between them.
  std::vector<io::StampedPose> scanTrajectory() const;
  std::vector<io::PosedScan> posedKeyframes() const;
  size_t anchors() const { return anchors_.size(); }
  double lastAnchorTime() const { return anchors_.empty() ? 0.0 : anchors_.back().timestamp; }
  const ScanAnchor* lastAnchor() const { return anchors_.empty() ? nullptr : &anchors_.back(); }

  // Keyframes, edges, the spatial index, anchors and odometry samples (the filter is written on
  // its own: Esdf::writeState). PipelineState.cpp.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r);

 private:
  struct OdometrySample {
    double timestamp;
    common::Pose2 odom;  // odometry pose at the reading
    size_t anchor;       // last anchor before it (npos: none yet)
  };
  struct OdometryCodec {
    static void write(common::BinaryWriter& w, const OdometrySample& s);
    static OdometrySample read(common::BinaryReader& r);
  };

  PerKeyframe<Keyframe> keyframes_;
  io::ScanStore scans_;  // keyframe k's scan has id k
  GraphEdgeLog edges_;
  KeyframeGrid index_;
  std::unique_ptr<esdf::Esdf> filter_;
  std::unique_ptr<KeyframeNodes> nodes_;
  PerKeyframe<ScanAnchor> anchors_;
  // Several per keyframe, read only when the trajectory is written: all but the newest wait in a
  // spill file.
  io::SpillLog<OdometrySample, OdometryCodec> odometry_;
};

}  // namespace urbanslam::slam
