#pragma once
// Where another session's map lies in this one, with no prior: the other session's keyframe
// scans, one every probe_spacing_m of its path, are each searched for in the whole map by place
// recognition (PlaceRecognizer, as `localize` does at its start). Every fix gives a transform
// from the session's frame to the map's. One fix can be a look-alike place (a repeated facade,
// a corridor of identical doors); the session's own trajectory is what tells: fixes of the right
// place agree on the transform, wrong ones scatter. The join is the largest set of fixes that
// agree, accepted only when it has at least min_agreeing fixes spread over min_span_m of the
// session's path, holds at least min_agreeing_share of all fixes, and no other set of
// min_agreeing fixes disagrees with it (two places that both explain the session: no join
// rather than a wrong one). The search stops at the first fix that makes the join: a log being
// mapped is joined as early as it can be, and a finished session is searched coarse to fine.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

struct SessionJoinOptions {
  double probe_spacing_m = 2.0;  // one place search per this much of the session's path
  // Two fixes agree when one's transform puts the other's keyframe within agree_m plus
  // agree_per_m times the session's path between them (its drift) of where the other was found,
  // and its heading within agree_deg.
  double agree_m = 1.0;
  double agree_per_m = 0.02;
  double agree_deg = 5.0;
  int min_agreeing = 4;
  double min_span_m = 6.0;  // of the session's path between the first and last agreeing fix
  double min_agreeing_share = 0.5;
};

struct SessionFix {
  size_t keyframe = 0;                                // the session's keyframe
  common::Pose2 pose;                                 // where it was found, map frame
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();  // as the localizer takes a place search's answer
  double margin_per_point = 0;
  common::Pose2 transform;  // session frame -> map frame, from this fix
};

struct SessionJoin {
  bool joined = false;
  std::string reason;       // why not
  common::Pose2 transform;  // session frame -> map frame (the agreeing fix's nearest to the session's start)
  // Its uncertainty at the session's first keyframe: the agreement's tolerance, grown by the
  // drift allowance over the session's path from there to that fix.
  Eigen::Matrix3d transform_cov = Eigen::Matrix3d::Identity();
  size_t probes = 0;              // place searches made
  std::vector<SessionFix> fixes;  // every fix found
  std::vector<size_t> agreeing;   // indices into fixes: the join's
  size_t rival = 0;               // the largest set of fixes that disagrees with the join
};

// The search kept up to date while the session grows (a run that joins a map as it goes):
// update() probes the keyframes added since the last call.
class SessionJoiner {
 public:
  // `map_options`: the map's options (its matcher and scan model). The map must outlive this.
  SessionJoiner(const Map& map, const PipelineOptions& map_options, SessionJoinOptions options = {});
  ~SessionJoiner();
  // Probes the session's keyframes not seen yet; returns the join as it stands. `progress`
  // (optional) is told the share of the session's keyframes seen.
  const SessionJoin& update(const Map& session, const std::function<void(double)>& progress = {});
  // A whole session at once, the probes coarse to fine along its path, until it is joined.
  const SessionJoin& searchAll(const Map& session, const std::function<void(double)>& progress = {});
  const SessionJoin& join() const { return join_; }

 private:
  void decide(const Map& session);
  void extendPath(const Map& session);
  bool probe(const Map& session, size_t keyframe);  // true: joined now

  struct Search;
  std::unique_ptr<Search> search_;
  SessionJoinOptions options_;
  SessionJoin join_;
  size_t seen_ = 0;           // session keyframes looked at
  std::vector<double> path_;  // the session's path length at each keyframe seen
  double next_probe_m_ = 0;
};

// The whole session at once (SessionJoiner::searchAll).
SessionJoin findSessionJoin(const Map& map, const PipelineOptions& map_options, const Map& session, const SessionJoinOptions& options = {},
                            const std::function<void(double)>& progress = {});

}  // namespace urbanslam::slam
