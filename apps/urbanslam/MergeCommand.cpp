// `urbanslam merge`: maps of separate sessions joined into one by place recognition and
// optimised together.
#include <filesystem>
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MapSession.h"
#include "urbanslam/slam/RunOutputs.h"

namespace urbanslam::cli {

int mergeCommand(const Argv& args) {
  ArgParser ap("urbanslam merge MAP MAP... [--out DIR] [--quiet] [--json]",
               "Joins the maps of separate runs (their map.usmap files or run folders) into the first one's frame:\n"
               "each later map's keyframes are searched for in the map so far by place recognition, with no\n"
               "idea where they lie; when enough of them agree on one place (and no other), the map is appended\n"
               "with its own odometry constraints, loops are closed between the two as a run closes them, and\n"
               "everything is optimised jointly. The maps must come from runs with the same options (all but\n"
               "[map] and [output]). The merged map continues the last session: `run --resume DIR` goes on\n"
               "from where its log ended.");
  ap.addPositional("MAP", "the map the others join (map.usmap or a run folder)");
  ap.addPositional("MAPS", "the maps to join to it, in order", true, true);
  ap.addOption("out", "DIR", "output folder (created if needed)", "out_merged");
  ap.addFlag("quiet", "no progress bar and no summary on stderr");
  ap.addFlag("json", "print stats.json as one JSON object on stdout");
  ap.addEpilog(
      "outputs in DIR: those of `urbanslam run` for the merged map (map.usmap, trajectories, clouds,\n"
      "grid, pose_graph.g2o, loop_closures.csv, stats.json with \"sessions\": per joined map the place\n"
      "searches, the fixes found and agreeing, the transform from its frame). Exit 1 when a map is not\n"
      "found in the map before it (its reason is printed; nothing is written), 2 for unreadable maps\n"
      "or maps of runs with other options.");
  if (!ap.parse(args)) return 0;
  std::vector<std::string> paths{ap.positional("MAP")};
  for (const auto& p : ap.positionals("MAPS")) paths.push_back(p);
  if (paths.size() < 2) throw common::InputError("merge: give at least two maps");
  const bool quiet = ap.flag("quiet");
  for (auto& p : paths) p = slam::mapFilePath(p);

  std::unique_ptr<slam::Pipeline> map = slam::loadMap(paths[0]);
  common::Json sessions = common::Json::array();
  for (size_t i = 1; i < paths.size(); ++i) {
    // The same options on every key that changes the result, as a continued run needs.
    const std::unique_ptr<slam::Pipeline> other = slam::loadMap(paths[i], &map->options());
    common::ProgressBar bar("merge " + std::filesystem::path(paths[i]).parent_path().filename().string(), 1000, !quiet);
    const slam::SessionJoin join = slam::findSessionJoin(map->map(), map->options(), other->map(), {},
                                                         [&](double f) { bar.update(static_cast<uint64_t>(f * 1000), "searching"); });
    bar.finish();
    if (!join.joined) {
      std::cerr << "urbanslam merge: " << paths[i] << " was not found in the map of " << paths[0]
                << (i > 1 ? " and the maps joined to it" : "") << ": " << join.reason << "; nothing written\n";
      if (ap.flag("json")) std::cout << slam::sessionJson(paths[i], join, map->keyframes().size()).dump() << "\n";
      return 1;
    }
    sessions.push(slam::sessionJson(paths[i], join, map->keyframes().size()));
    map->appendSession(*other, join);
  }

  std::string out = ap.option("out");
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  const slam::StagedMapFile map_file(out, *map);
  map->finish();
  std::string inputs;
  for (size_t i = 1; i < paths.size(); ++i) inputs += (i > 1 ? " " : "") + paths[i];
  const common::Json stats = slam::writeRunOutputs(
      *map, out,
      {inputs, "usmap", paths[0] + " (its saved options)", slam::optionsToIni(map->options()), map_file.path(), paths[0], sessions});
  if (ap.flag("json")) std::cout << stats.dump() << "\n";
  if (!quiet)
    std::cerr << "urbanslam merge: " << paths.size() << " maps, " << map->keyframes().size() << " keyframes; outputs in "
              << std::filesystem::absolute(out).string() << "/\n";
  return 0;
}

}  // namespace urbanslam::cli
