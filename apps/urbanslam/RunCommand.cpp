// `urbanslam run`: the main job, as icp-slam/rbpf-slam do it (a log in, a folder of outputs out).
#include <filesystem>
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "DefaultPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/Checkpoint.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MapMerge.h"
#include "urbanslam/slam/MapSession.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/RunOutputs.h"

namespace urbanslam::cli {

namespace {

class ProgressObserver : public slam::PipelineObserver {
 public:
  explicit ProgressObserver(common::ProgressBar& bar) : bar_(bar) {}
  void onStep(const slam::StepEvent& e) override {
    bar_.update(static_cast<uint64_t>(e.progress * 1000),
                std::to_string(e.scans) + " scans, " + std::to_string(e.keyframes) + " keyframes");
  }

 private:
  common::ProgressBar& bar_;
};

}  // namespace

int runCommand(const Argv& args) {
  ArgParser ap("urbanslam run [--ini FILE] [--out DIR] [--quiet] [--json] [--resume MAP | --map MAP] [--checkpoint-every N [--continue]] [LOG | --simulate CITY_INI]",
               "Builds a map and trajectory from a log: MRPT rawlog (either layout, gzipped or not),\n"
               "CARMEN log (raw or Freiburg-corrected), GMapping gfs log, Victoria Park (folder or zip) or a\n"
               "folder of camera images (one keyframe per image; image loop proposals need [loop_closure] image_detector).");
  ap.addPositional("LOG", "input log; default: the shipped rawlogs/intel.rawlog", false);
  ap.addOption("simulate", "CITY_INI",
               "map a simulated city drive streamed straight from the simulator (no file; see\n"
               "`urbanslam simulate`) instead of a LOG");
  ap.addOption("ini", "FILE", "configuration (see ini/default.ini for every key); with --resume: the map's own by default",
               "ini/default.ini");
  ap.addOption("resume", "MAP",
               "continue the map of an earlier run (its map.usmap, or its output folder) with LOG, which\n"
               "must start where that run's log ended (e.g. the rest of a split log); the result is that of\n"
               "one run over both (separate maps in MAP are carried along). An --ini may change only [map]\n"
               "and [output] keys");
  ap.addOption("map", "MAP",
               "map LOG as a new session of the map of an earlier run (its map.usmap, or its output folder),\n"
               "starting anywhere: LOG is mapped on its own until place recognition finds it in the map\n"
               "(a few agreeing places), then joined to the map and continued inside it; a LOG that never\n"
               "meets the map ends as a map of its own, with MAP kept beside it as a separate map in the\n"
               "output's map.usmap (stats.json: sessions, separate_maps). MAP's own separate maps are\n"
               "searched for again: the new session may link them. An --ini may change only [map] and\n"
               "[output] keys");
  ap.addOption("out", "DIR", "output folder (created if needed)", "out");
  ap.addOption("checkpoint-every", "N",
               "save the run every N keyframes to DIR.checkpoint/ (its map and how far it read LOG), so that\n"
               "an interrupted run goes on with --continue; removed when the run completes", "0");
  ap.addFlag("continue",
             "go on with the interrupted run whose checkpoint is DIR.checkpoint/: the same LOG (or city) is\n"
             "read from where the checkpoint left it, and the run ends as one never interrupted. An --ini\n"
             "may change only [map] and [output] keys");
  ap.addFlag("quiet", "no progress bar and no summary on stderr");
  ap.addFlag("json", "print stats.json as one JSON object on stdout");
  ap.addEpilog(
      "outputs in DIR: trajectory_keyframes.tum, trajectory_odometry.tum, trajectory_scans.tum (every\n"
      "scan placed by matching), reference.tum (when the log has one), map.ply/.pcd/.xyz,\n"
      "map.simplemap, grid.png + grid.yaml, pose_graph.g2o, map.usmap (the state --resume continues),\n"
      "loop_closures.csv (every hypothesis, laser or image, and its fate), config.ini, stats.json.\n"
      "DIR appears complete at the end (written beside it, then swapped in): it is replaced only when\n"
      "it is empty or holds an earlier run.");
  if (!ap.parse(args)) return 0;

  if (ap.has("simulate") && !ap.positional("LOG").empty())
    throw common::InputError("run: give either a LOG or --simulate CITY_INI, not both");
  if (ap.has("resume") && !ap.has("simulate") && ap.positional("LOG").empty())
    throw common::InputError("run --resume: give the LOG that continues the map");
  if (ap.has("resume") && ap.has("map")) throw common::InputError("run: give either --resume MAP or --map MAP, not both");
  if (ap.has("map") && !ap.has("simulate") && ap.positional("LOG").empty())
    throw common::InputError("run --map: give the LOG to map into the map");
  if (ap.flag("continue") && (ap.has("resume") || ap.has("map")))
    throw common::InputError("run --continue: the checkpoint holds the map; give neither --resume nor --map");
  const long every = ap.optionInt("checkpoint-every");
  if (every < 0) throw common::InputError("run --checkpoint-every: a number of keyframes, 0 for none (got " + std::to_string(every) + ")");
  if (every > 0 && ap.has("map")) throw common::InputError("run --map: a session joined to a map cannot be checkpointed (map its LOG alone)");
  const std::string log = ap.has("simulate")             ? ap.option("simulate")
                          : ap.positional("LOG").empty() ? defaultRawlog()
                                                         : ap.positional("LOG");
  const bool quiet = ap.flag("quiet");
  std::string out = ap.option("out");
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  const std::string checkpoint = slam::checkpointPath(out);
  const std::string map = ap.has("resume") ? slam::mapFilePath(ap.option("resume"))
                          : ap.has("map")  ? slam::mapFilePath(ap.option("map"))
                                           : "";
  // Resuming without --ini keeps the map's own options.
  std::string ini = ap.has("ini") ? ap.option("ini") : map.empty() && !ap.flag("continue") ? defaultIni() : "";
  std::string resolved;
  slam::PipelineOptions options;
  if (!ini.empty()) {
    options = slam::loadPipelineOptions(ini, &resolved);
    slam::resolveDefaultPaths(options, projectHome());
  }
  // The progress observer outlives the pipeline: global SLAM's thread may still call it while an
  // error from reading the log unwinds this function.
  common::ProgressBar bar("run", 1000, !quiet);
  ProgressObserver progress(bar);
  // The maps of the output's map.usmap: [0] the one this run builds, then a map file's separate
  // maps (MapFile.h), carried along.
  std::vector<slam::NamedMap> maps;
  slam::CheckpointInfo earlier;
  if (ap.flag("continue")) {
    slam::Checkpoint c = slam::loadCheckpoint(checkpoint, ini.empty() ? nullptr : &options, log);
    earlier = c.info;
    maps.push_back({std::move(c.pipeline), {c.info.resumed_map.empty() ? log : c.info.resumed_map}, 0});
  } else {
    std::vector<std::unique_ptr<slam::Pipeline>> separate;
    maps.push_back(
        {map.empty() ? std::make_unique<slam::Pipeline>(options) : slam::loadMap(map, ini.empty() ? nullptr : &options, &separate),
         {map.empty() ? log : map},
         0});
    for (auto& m : slam::namedSeparateMaps(std::move(separate), map, 0)) maps.push_back(std::move(m));
  }
  if (ini.empty()) {
    resolved = slam::optionsToIni(maps.front().map->options());
    ini = (map.empty() ? checkpoint : map) + " (its saved options)";
  }

  // The simulator is a data source like a file reader: a drive of any length streams through.
  std::unique_ptr<io::DataSource> source =
      ap.has("simulate") ? std::make_unique<sim::SimulatedSource>(sim::loadSimOptions(log)) : io::openDataSource(log);
  common::Json sessions;
  bool joined = false;
  if (ap.has("map")) {
    // A new session of the map: on its own until it is found in the map, then inside it.
    slam::SessionRun s = slam::runSessionInMap(std::move(maps.front().map), *source, {&progress});
    joined = s.join.joined;
    sessions = common::Json::array();
    sessions.push(slam::sessionJson(log, s.join, s.keyframes_before, s.joined_at_s));
    if (!quiet && !s.join.joined)
      std::cerr << "urbanslam run: " << log << " was not found in " << map << " (" << s.join.reason << "): its map is its own\n";
    // The map that holds the session first (the one a resumed run continues), then the maps it
    // was not joined to: the session may link them now.
    maps.front() = joined ? slam::NamedMap{std::move(s.pipeline), {map, log}} : slam::NamedMap{std::move(s.pipeline), {log}};
    if (s.map) maps.insert(maps.begin() + 1, slam::NamedMap{std::move(s.map), {map}, 0});
    if (maps.size() > 1) {
      slam::MergedMaps merged = slam::mergeMaps(std::move(maps));
      for (const auto& j : merged.sessions) sessions.push(j);
      maps = std::move(merged.maps);
      if (!quiet && maps.size() > 1)
        std::cerr << "urbanslam run: " << maps.size() - 1 << " separate map" << (maps.size() > 2 ? "s" : "") << " kept in map.usmap\n";
    }
  } else {
    slam::Pipeline& p = *maps.front().map;
    const std::uint64_t before = p.stats().measurements - earlier.input_measurements;  // a resumed map's own
    if (ap.flag("continue")) {
      if (!quiet)
        std::cerr << "urbanslam run: continuing from " << checkpoint << " (" << earlier.keyframes << " keyframes, "
                  << earlier.input_measurements << " measurements of " << log << " read)\n";
      slam::skipMeasurements(*source, earlier.input_measurements, log);
    } else {
      earlier.input = std::filesystem::absolute(log).string();
      earlier.resumed_map = map;
    }
    p.addObserver(&progress);
    slam::Checkpointer saver(checkpoint, static_cast<size_t>(every), earlier, before);
    slam::runCheckpointed(p, *source, saver);
  }
  slam::Pipeline* const pipeline = maps.front().map.get();
  // The map is saved before finish() (StagedMapFile).
  const slam::StagedMapFile map_file(out, *pipeline, slam::separateMaps(maps));
  pipeline->finish(*source);
  bar.finish();
  // A log without a single keyframe has nothing to map: outputs would only look like a run.
  if (pipeline->keyframes().empty()) {
    const size_t scans = pipeline->stats().scans;
    throw common::InputError(log + (scans == 0 ? ": no laser scans (nor images) in the log: nothing to map"
                                               : ": none of its " + std::to_string(scans) + " laser scans could be used: nothing to map"));
  }

  const slam::RunInfo info{
      log, source->format(), ini, resolved, map_file.path(), ap.has("map") && !joined ? "" : map, sessions, slam::separateMapsJson(maps)};
  const common::Json stats = slam::writeRunOutputs(*pipeline, out, info);
  // The outputs hold the whole run now (map.usmap continues it): the checkpoint has done its job.
  std::error_code ec;
  if (every > 0 || ap.flag("continue")) std::filesystem::remove_all(checkpoint, ec);
  if (ap.flag("json")) std::cout << stats.dump() << "\n";
  if (!quiet) {
    const auto& t = stats.at("timing");
    std::cerr << "urbanslam run: " << pipeline->stats().scans_used << " scans, " << pipeline->keyframes().size() << " keyframes, "
              << stats.at("counts").at("map_points").asNumber() << " map points in " << t.at("wall_s").asNumber() << " s ("
              << t.at("real_time_factor").asNumber() << "x real time)\n"
              << "outputs in " << std::filesystem::absolute(out).string() << "/ (grid.png, map.ply, "
              << "trajectory_keyframes.tum, stats.json, ...)\n";
  }
  return 0;
}

}  // namespace urbanslam::cli
