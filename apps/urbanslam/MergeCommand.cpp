// `urbanslam merge`: maps of separate sessions joined into one by place recognition and
// optimised together.
#include <filesystem>
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MapMerge.h"
#include "urbanslam/slam/MapSession.h"
#include "urbanslam/slam/RunOutputs.h"

namespace urbanslam::cli {

int mergeCommand(const Argv& args) {
  ArgParser ap("urbanslam merge MAP MAP... [--out DIR] [--quiet] [--json]",
               "Joins the maps of separate runs (their map.usmap files or run folders) into the first one's frame:\n"
               "each later map is searched for in the maps so far by place recognition, with no idea where it\n"
               "lies; when enough of its keyframes agree on one place (and no other), it is appended with its\n"
               "own odometry constraints, loops are closed between them as a run closes them, and everything is\n"
               "optimised jointly. Then the maps kept apart so far are searched for again: the new map may link\n"
               "them. A map found nowhere stays a separate map, in its own frame, in the output's map.usmap,\n"
               "until a later merge or `run --map` links it. The maps must come from runs with the same options\n"
               "(all but [map] and [output]). The merged map continues the last session joined to the first:\n"
               "`run --resume DIR` goes on from where its log ended.");
  ap.addPositional("MAP", "the map the others join (map.usmap or a run folder)");
  ap.addPositional("MAPS", "the maps to join to it, in order", true, true);
  ap.addOption("out", "DIR", "output folder (created if needed)", "out_merged");
  ap.addFlag("quiet", "no progress bar and no summary on stderr");
  ap.addFlag("json", "print stats.json as one JSON object on stdout");
  ap.addEpilog(
      "A map file may itself hold separate maps (an earlier merge's): each takes part as a map of its own.\n"
      "outputs in DIR: those of `urbanslam run` for the first map with everything joined to it\n"
      "(map.usmap with the separate maps too, trajectories, clouds, grid, pose_graph.g2o,\n"
      "loop_closures.csv, stats.json with \"sessions\": per join the map found, where, the place\n"
      "searches, the fixes found and agreeing, the transform from its frame; per map kept separate why,\n"
      "and \"separate_maps\": their keyframes and sessions). Exit 2 for unreadable maps or maps of\n"
      "runs with other options.");
  if (!ap.parse(args)) return 0;
  std::vector<std::string> paths{ap.positional("MAP")};
  for (const auto& p : ap.positionals("MAPS")) paths.push_back(p);
  if (paths.size() < 2) throw common::InputError("merge: give at least two maps");
  const bool quiet = ap.flag("quiet");
  for (auto& p : paths) p = slam::mapFilePath(p);

  // Every map of every file, in order; the same options on every key that changes the result,
  // as a continued run needs.
  std::vector<slam::NamedMap> maps;
  for (size_t i = 0; i < paths.size(); ++i) {
    std::vector<std::unique_ptr<slam::Pipeline>> separate;
    const int group = static_cast<int>(i);  // one file's maps were kept apart by the run that wrote it
    maps.push_back({slam::loadMap(paths[i], i == 0 ? nullptr : &maps.front().map->options(), &separate), {paths[i]}, group});
    for (auto& m : slam::namedSeparateMaps(std::move(separate), paths[i], group)) maps.push_back(std::move(m));
  }
  common::ProgressBar bar("merge", 1000, !quiet);
  slam::MergedMaps merged =
      slam::mergeMaps(std::move(maps), {}, [&](const std::string&, double f) { bar.update(static_cast<uint64_t>(f * 1000), "searching"); });
  bar.finish();
  slam::Pipeline& map = *merged.maps.front().map;
  if (!quiet)
    for (size_t i = 1; i < merged.maps.size(); ++i)
      std::cerr << "urbanslam merge: " << merged.maps[i].sessions.front() << " was not found in the other maps: kept as separate map " << i
                << ", in its own frame\n";

  std::string out = ap.option("out");
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  const slam::StagedMapFile map_file(out, map, slam::separateMaps(merged.maps));
  map.finish();
  std::string inputs;
  for (size_t i = 1; i < paths.size(); ++i) inputs += (i > 1 ? " " : "") + paths[i];
  common::Json sessions = common::Json::array();
  for (const auto& j : merged.sessions) sessions.push(j);
  const slam::RunInfo info{inputs,   "usmap",  paths[0] + " (its saved options)",  slam::optionsToIni(map.options()), map_file.path(),
                           paths[0], sessions, slam::separateMapsJson(merged.maps)};
  const common::Json stats = slam::writeRunOutputs(map, out, info);
  if (ap.flag("json")) std::cout << stats.dump() << "\n";
  if (!quiet)
    std::cerr << "urbanslam merge: " << paths.size() << " maps, " << map.keyframes().size() << " keyframes in the first"
              << (merged.maps.size() > 1 ? " and " + std::to_string(merged.maps.size() - 1) + " separate" : std::string())
              << "; outputs in " << std::filesystem::absolute(out).string() << "/\n";
  return 0;
}

}  // namespace urbanslam::cli
