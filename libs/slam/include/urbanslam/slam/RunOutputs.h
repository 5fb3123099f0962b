#pragma once
// Writes everything `urbanslam run` produces into one folder: trajectories (TUM), map point
// clouds, .simplemap, occupancy grid, stats.json and the resolved config.ini. The folder is
// replaced as a whole (common::AtomicFolder): it appears complete, holding one run, or not at
// all; an existing folder that is neither empty nor a run's is refused (InputError), never
// deleted. stats.json still comes last. map.usmap, the state another run can continue
// (MapFile.h), is written before finish() to a temporary file, which RunInfo names and which is
// moved into the folder.
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::slam {

struct RunInfo {
  std::string input_path, input_format, ini_path, resolved_ini;
  std::string map_file;     // map.usmap written before finish() (writeMapFile), moved in; empty: none
  std::string resumed_map;  // the map this run continued, "" for a run from scratch
  // Sessions joined to the map (`run --map`, `merge`): stats.json's "sessions" (sessionJson);
  // null for none.
  common::Json sessions;
  // The maps map.usmap holds besides this one, each in its own frame (MapMerge.h's
  // separateMapsJson): stats.json's "separate_maps"; null for none.
  common::Json separate_maps;
};

// map.usmap for the run folder `dir`, staged: the pipeline's state saved now, before finish()
// (which drops the closures still awaiting confirmation that a continued run may yet confirm),
// streamed to a temporary file beside `dir`, which writeRunOutputs moves into the folder
// (RunInfo::map_file). Temporaries of earlier killed runs are removed first, and this one is
// removed when the run fails before the move. A pipeline without keyframes has no map: path()
// is then empty. Throws InputError when dir's parent cannot be created.
class StagedMapFile {
 public:
  // `separate`: the file's maps besides the pipeline's (MapFile.h), written with it.
  StagedMapFile(const std::string& dir, const Pipeline& pipeline, const std::vector<const Pipeline*>& separate = {});
  ~StagedMapFile();
  StagedMapFile(const StagedMapFile&) = delete;
  StagedMapFile& operator=(const StagedMapFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The keyframe pose graph (estimates, motion and loop-closure constraints) as g2o.
void writePoseGraphG2o(const Pipeline& pipeline, const std::string& path);

// Returns the stats.json content that was written.
common::Json writeRunOutputs(const Pipeline& pipeline, const std::string& dir, const RunInfo& info);

}  // namespace urbanslam::slam
