#include "urbanslam/slam/MapMerge.h"

#include <map>

#include "urbanslam/slam/MapSession.h"

namespace urbanslam::slam {

namespace {

// Searches for maps[b] in maps[a] (a < b) and, found, appends it there; true when joined. A
// search that fails leaves its account in `misses` (by the map's first session).
bool tryJoin(std::vector<NamedMap>& maps, size_t a, size_t b, const SessionJoinOptions& options,
             const std::function<void(const std::string&, double)>& progress, std::vector<common::Json>& log,
             std::map<std::string, common::Json>& misses) {
  if (maps[a].apart_group >= 0 && maps[a].apart_group == maps[b].apart_group) return false;  // searched before, as they are
  Pipeline& into = *maps[a].map;
  const NamedMap& other = maps[b];
  const std::string name = other.sessions.front();
  const SessionJoin join = findSessionJoin(into.map(), into.options(), other.map->map(), options, [&](double f) {
    if (progress) progress(name, f);
  });
  if (!join.joined) {
    misses[name] = sessionJson(name, join, 0);
    return false;
  }
  common::Json j = sessionJson(name, join, into.keyframes().size());
  j["into"] = maps[a].sessions.front();
  if (other.sessions.size() > 1) {
    common::Json with = common::Json::array();
    for (size_t i = 1; i < other.sessions.size(); ++i) with.push(other.sessions[i]);
    j["with"] = std::move(with);  // the sessions that came with it, joined to it before
  }
  log.push_back(std::move(j));
  into.appendSession(*other.map, join);
  maps[a].sessions.insert(maps[a].sessions.end(), other.sessions.begin(), other.sessions.end());
  maps[a].apart_group = -1;  // it grew: worth searching against everything again
  maps.erase(maps.begin() + static_cast<std::ptrdiff_t>(b));
  return true;
}

}  // namespace

MergedMaps mergeMaps(std::vector<NamedMap> maps, const SessionJoinOptions& options,
                     const std::function<void(const std::string&, double)>& progress) {
  MergedMaps out;
  std::map<std::string, common::Json> misses;
  for (NamedMap& next : maps) {
    out.maps.push_back(std::move(next));
    size_t at = out.maps.size() - 1;
    bool joined = false;
    // The new map into the first map that holds it...
    for (size_t a = 0; a < at && !joined; ++a)
      if (tryJoin(out.maps, a, at, options, progress, out.sessions, misses)) {
        at = a;
        joined = true;
      }
    if (!joined) continue;  // found nowhere (yet)
    // ...then every other map against the one that grew, until nothing more links.
    for (bool linked = true; linked;) {
      linked = false;
      for (size_t o = 0; o < out.maps.size() && !linked; ++o) {
        if (o == at) continue;
        const size_t a = std::min(o, at), b = std::max(o, at);
        if (tryJoin(out.maps, a, b, options, progress, out.sessions, misses)) {
          at = a;
          linked = true;
        }
      }
    }
  }
  for (size_t i = 1; i < out.maps.size(); ++i) {
    const std::string& name = out.maps[i].sessions.front();
    common::Json j = misses.count(name) ? misses[name] : common::Json::object();  // its last search
    j["name"] = name;
    j["joined"] = false;
    j["reason"] =
        (misses.count(name) ? misses[name].at("reason").asString() + "; " : std::string()) + "kept as a separate map in its own frame";
    j["separate_map"] = i;
    out.sessions.push_back(std::move(j));
  }
  return out;
}

std::vector<NamedMap> namedSeparateMaps(std::vector<std::unique_ptr<Pipeline>> separate, const std::string& file, int apart_group) {
  std::vector<NamedMap> out;
  for (size_t k = 0; k < separate.size(); ++k)
    out.push_back({std::move(separate[k]), {file + " (separate map " + std::to_string(k + 1) + ")"}, apart_group});
  return out;
}

common::Json separateMapsJson(const std::vector<NamedMap>& maps) {
  if (maps.size() < 2) return common::Json();
  common::Json out = common::Json::array();
  for (size_t i = 1; i < maps.size(); ++i) {
    common::Json j = common::Json::object();
    j["keyframes"] = maps[i].map->keyframes().size();
    common::Json s = common::Json::array();
    for (const auto& n : maps[i].sessions) s.push(n);
    j["sessions"] = std::move(s);
    out.push(std::move(j));
  }
  return out;
}

std::vector<const Pipeline*> separateMaps(const std::vector<NamedMap>& maps) {
  std::vector<const Pipeline*> out;
  for (size_t i = 1; i < maps.size(); ++i) out.push_back(maps[i].map.get());
  return out;
}

}  // namespace urbanslam::slam
