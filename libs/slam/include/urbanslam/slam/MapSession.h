#pragma once
// A log mapped as a new session of a saved map whose start in that map is unknown (`urbanslam
// run --map`): the log is mapped on its own, in a frame of its own, while place recognition
// looks for its keyframes in the map (SessionJoiner, one search every few metres). Once the
// session is joined, it is appended to the map (Pipeline::appendSession) and the rest of the log
// continues inside the map, as a continued run would: its loops close against the map and its
// local SLAM takes the corrections. A session that is never joined ends as a map of its own.
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/SessionJoin.h"

namespace urbanslam::slam {

struct SessionRun {
  // The map with the session in it, or the session alone when it was never joined; its input
  // read to the end, global SLAM caught up, not finished (the map can still be saved).
  std::unique_ptr<Pipeline> pipeline;
  // The map, when the session was never joined to it (then it stays a map of its own).
  std::unique_ptr<Pipeline> map;
  SessionJoin join;
  double joined_at_s = 0;       // log time of the keyframe at which the join was found
  size_t keyframes_before = 0;  // the map's keyframes before the session's
};

// `map`: loaded from its file, not finished. `observers` are added to whichever pipeline runs.
SessionRun runSessionInMap(std::unique_ptr<Pipeline> map, io::DataSource& source, const std::vector<PipelineObserver*>& observers = {},
                           const SessionJoinOptions& options = {});

// What stats.json says of a session: `name` (its map or log), joined or why not, the place
// searches made, the fixes found and agreeing, the transform from its frame into the map's, the
// map's keyframes before its own and (a log mapped into the map) the log time it was joined at.
common::Json sessionJson(const std::string& name, const SessionJoin& join, size_t keyframes_before, double joined_at_s = -1);

}  // namespace urbanslam::slam
