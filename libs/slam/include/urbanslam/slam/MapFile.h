#pragma once
// map.usmap: a run's state saved so that another run continues it with a new log, with the same
// result as one run over both logs in a row. A versioned little-endian binary file: signature,
// format version, payload length, FNV-1a 64 checksum of the payload, then the payload's tagged
// sections (the resolved options first, then Pipeline::writeState, then the separate maps).
// libs/slam/README.md ("The map file") documents every byte.
//
// One file can hold several maps, each in a frame of its own: sessions that place recognition
// has not linked (`merge`, `run --map`) stay separate until a later session joins them. The
// first map is the one a run continues and the commands work on; the separate ones are carried
// along, with the same options.
#include <cstdint>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::slam {

constexpr const char* kMapFileName = "map.usmap";
constexpr std::uint32_t kMapFormatVersion = 15;
// Version 3 files (no separate maps), 4 (no heading corrections of local SLAM), 5 (no record of
// which camera closures measured bearing and heading only), 6 (no record of what confirmed a
// closure), 7 (every step's duration instead of their histograms), 8 (no record of the
// filter's factors since its last factorisation), 9 (every keyframe a filter pose of its own),
// 10 (a reduced pose graph that hung keyframes at their closures: refused when it has one) and
// 11 (no record of which closures left the ambiguity restarts out), 12 (no sensor positions in
// local SLAM's point sets), 13 (no loop-search cursor) and 14 (no odometry outvotes of local
// SLAM) are read as well.
constexpr std::uint32_t kOldestMapFormatVersion = 3;

// The map of the pipeline's current state written to `out` from its start, streamed (the
// stream is read back for the checksum); `name` for errors. Call it before finish() (after
// finish() the state cannot be continued: std::logic_error). `separate`: the file's other maps
// (not finished either).
void writeMap(const Pipeline& pipeline, std::iostream& out, const std::string& name, const std::vector<const Pipeline*>& separate = {});
// The same as bytes in memory (tests, fuzzing).
std::string encodeMap(const Pipeline& pipeline, const std::vector<const Pipeline*>& separate = {});
// The same written to `path` as it is (the caller renames it into place).
void writeMapFile(const Pipeline& pipeline, const std::string& path, const std::vector<const Pipeline*>& separate = {});
// The same written atomically: a temporary beside `path`, renamed when complete.
void saveMap(const Pipeline& pipeline, const std::string& path, const std::vector<const Pipeline*>& separate = {});

// The map file named by the user: the file itself, or the run folder holding map.usmap.
std::string mapFilePath(const std::string& file_or_run_folder);

// What a loaded map is for: continued (run --resume, --map, merge), or only read (localize, whose
// localizer reads the keyframes and their images' words and never adds to the map).
enum class MapUse { Continue, Localize };

// The pipeline a map file holds, ready for its next measurement. `options` (optional): the
// options the continued run asks for, which must equal the map's on every key that changes the
// result (all but [map] and [output]; InputError naming the key otherwise); the pipeline then
// runs with them. Without, it runs with the map's own. Throws common::InputError naming the file
// for a file that is not a map, of another format version, truncated or corrupt. `separate`
// (optional) receives the file's separate maps, with the same options; without, they are
// checked by the checksum only and skipped. A map whose run kept a Tree of Words database over
// camera images cannot be continued (the file holds the keyframes' words, not the database):
// InputError, unless `use` is Localize.
std::unique_ptr<Pipeline> loadMap(const std::string& path, const PipelineOptions* options = nullptr,
                                  std::vector<std::unique_ptr<Pipeline>>* separate = nullptr, MapUse use = MapUse::Continue);

}  // namespace urbanslam::slam
