#pragma once
// Maps of separate sessions, each in its own frame, joined wherever place recognition links them
// (`urbanslam merge`, `urbanslam run --map`). Each map in turn is searched for in the maps so far
// (findSessionJoin), the first map first; found, it is appended to that map (appendSession) and
// optimised with it. Then that map is searched for in every other map kept so far, and they in
// it: the new session may be the one that links two maps none of the earlier sessions could, and
// so on until nothing more links. A map found nowhere stays separate, in its own frame, until a
// later session joins it. A map joins the one with the lower index, so the first map's frame is
// the result's.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/SessionJoin.h"

namespace urbanslam::slam {

struct NamedMap {
  std::unique_ptr<Pipeline> map;  // loaded, not finished; all with the same options
  // Its sessions' names (a map file's, or the log that made it); a map made by merging has several.
  std::vector<std::string> sessions;
  // Maps with the same group (>= 0) were searched for in each other as they are and not linked:
  // the maps of one file. They are not searched again until one of them grows (group -1 then).
  int apart_group = -1;
};

// A map file's separate maps (loadMap), named after the file ("FILE (separate map K)"), in the
// file's group.
std::vector<NamedMap> namedSeparateMaps(std::vector<std::unique_ptr<Pipeline>> separate, const std::string& file, int apart_group);

struct MergedMaps {
  std::vector<NamedMap> maps;  // [0]: the first map's frame, with everything joined to it; then the separate maps
  // One entry per search that decided something (sessionJson of the map searched for, which
  // "joined" the map "into"), and per map that ended separate ("joined": false, its reason).
  std::vector<common::Json> sessions;
};

// `progress` (optional): the map being searched for (its first session's name) and the share of
// that search done.
MergedMaps mergeMaps(std::vector<NamedMap> maps, const SessionJoinOptions& options = {},
                     const std::function<void(const std::string&, double)>& progress = {});

// stats.json's "separate_maps": per map after the first, its keyframes and sessions (null when
// there are none).
common::Json separateMapsJson(const std::vector<NamedMap>& maps);

// The maps after the first, as saveMap and StagedMapFile take them.
std::vector<const Pipeline*> separateMaps(const std::vector<NamedMap>& maps);

}  // namespace urbanslam::slam
