#include "urbanslam/slam/MapSession.h"

namespace urbanslam::slam {

common::Json sessionJson(const std::string& name, const SessionJoin& join, size_t keyframes_before, double joined_at_s) {
  common::Json j = common::Json::object();
  j["name"] = name;
  j["joined"] = join.joined;
  if (!join.joined) j["reason"] = join.reason;
  j["place_searches"] = join.probes;
  j["fixes"] = join.fixes.size();
  j["fixes_agreeing"] = join.agreeing.size();
  j["scans_agreeing"] = join.agreeing_scans;
  size_t by_classifier = 0;
  for (const SessionFix& f : join.fixes) by_classifier += f.detector == Proposer::Laser ? 1 : 0;
  j["fixes_laser"] = by_classifier;
  j["fixes_rival"] = join.rival;
  if (join.joined) {
    common::Json t = common::Json::object();
    t["x"] = join.transform.x;
    t["y"] = join.transform.y;
    t["phi"] = join.transform.phi;
    j["transform"] = std::move(t);
    j["first_keyframe"] = keyframes_before;
    if (joined_at_s >= 0) j["joined_at_s"] = joined_at_s;
  }
  return j;
}

SessionRun runSessionInMap(std::unique_ptr<Pipeline> map, io::DataSource& source, const std::vector<PipelineObserver*>& observers,
                           const SessionJoinOptions& options) {
  SessionRun out;
  out.keyframes_before = map->keyframes().size();
  auto session = std::make_unique<Pipeline>(map->options());
  for (auto* o : observers) session->addObserver(o);
  {
    SessionJoiner joiner(map->map(), map->options(), options);
    size_t seen = 0;
    while (session->step(source)) {
      if (session->keyframesMade() == seen) continue;
      // The keyframe's pose and scan are global SLAM's to give: wait for them.
      session->waitForGlobalSlam(source);
      seen = session->keyframesMade();
      out.join = joiner.update(session->map());
      if (!out.join.joined) continue;
      out.joined_at_s = session->keyframes().back().timestamp;
      map->appendSession(*session, out.join);
      break;
    }
  }
  if (!out.join.joined) {
    session->waitForGlobalSlam(source);
    out.pipeline = std::move(session);
    out.map = std::move(map);
    return out;
  }
  for (auto* o : observers) map->addObserver(o);
  map->runInput(source);
  out.pipeline = std::move(map);
  return out;
}

}  // namespace urbanslam::slam
