// `urbanslam localize`: track the vehicle of a log in a map an earlier run built (its
// map.usmap), which stays as it is.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/slam/LocalizationOutputs.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/MapFile.h"

namespace urbanslam::cli {

namespace {

common::Pose2 parsePose(const std::string& text) {
  std::stringstream ss(text);
  double v[3];
  char comma1 = 0, comma2 = 0;
  if (!(ss >> v[0] >> comma1 >> v[1] >> comma2 >> v[2]) || comma1 != ',' || comma2 != ',' || !(ss >> std::ws).eof() ||
      !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw common::InputError("localize --initial: expected x,y,phi (metres, metres, radians), got '" + text + "'");
  return {v[0], v[1], common::wrapToPi(v[2])};
}

size_t parseSeparateMap(const std::string& text) {
  size_t used = 0;
  unsigned long long k = 0;
  try {
    k = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || text[0] == '-' || k > 1000000)
    throw common::InputError("localize --separate-map: expected a whole number (0: the first map), got '" + text + "'");
  return static_cast<size_t>(k);
}

}  // namespace

int localizeCommand(const Argv& args) {
  ArgParser ap("urbanslam localize --map MAP LOG [--initial x,y,phi] [--separate-map K] [--no-smoothing] [--out DIR] [--quiet] [--json]",
               "Tracks the vehicle of LOG in the map of an earlier `urbanslam run` (its map.usmap, or its output\n"
               "folder), which is not changed. Local SLAM runs over the log as in a mapping run; its motion\n"
               "predicts each scan's pose, which is matched against the map's scans near it (once the matches\n"
               "confirm the pose, once per keyframe spacing of travel). Without --initial, and whenever the\n"
               "matches stop supporting the pose (lost), the map is searched for the scan's place until one\n"
               "place clearly wins: the whole map, or, once matches have confirmed the pose, only where the\n"
               "motion from it can have gone. With a camera in LOG and a map whose keyframes kept their images'\n"
               "words ([loop_closure] image_detector = tree_of_words), a search the scan alone leaves ambiguous\n"
               "is made again near the keyframes whose images look like the latest image (stats.json:\n"
               "image_place_searches, image_relocalisations).\n"
               "A map file that holds separate maps (`merge`, `run --map`; stats.json's separate_maps lists\n"
               "them): the vehicle is localized in the one --separate-map names, in the first with --initial,\n"
               "and otherwise searched for in all of them, side by side, until one finds its place; that map\n"
               "goes on alone (stats.json: separate_map, maps_searched).");
  ap.addPositional("LOG", "the log to localize (any format `run` reads)");
  ap.addOption("map", "MAP", "the map: a map.usmap file or the run folder holding one (required)");
  ap.addOption("separate-map", "K",
               "localize in the map file's K-th separate map (in that map's own frame; 0: the first map); default: searched "
               "in every map of the file (the first with --initial)");
  ap.addOption("initial", "x,y,phi", "the vehicle's pose at the first scan in the map frame (m, m, rad); default: searched");
  ap.addOption("out", "DIR", "output folder (created if needed)", "out_localize");
  ap.addFlag("no-smoothing",
             "no local SLAM: every scan predicted by the odometry and matched against the map, and trajectory_scans.tum "
             "holds the poses as tracked (faster)");
  ap.addFlag("quiet", "no progress bar and no summary on stderr");
  ap.addFlag("json", "print stats.json as one JSON object on stdout");
  ap.addEpilog(
      "outputs in DIR: trajectory_scans.tum (the tracked scans, smoothed given the whole log: local SLAM's\n"
      "motion between scans weighed against the map's matches; `urbanslam eval DIR --relations F` scores\n"
      "it), trajectory_online.tum (the same scans as tracked at each scan), localization.csv (every\n"
      "scan as tracked then: time, x, y, phi, covariance upper triangle xx xy xphi yy yphi phiphi, state\n"
      "tracking|lost), stats.json (counts, time lost, relocalisations, wall time, real-time\n"
      "factor). DIR appears complete at the end; it is replaced only when it is empty or\n"
      "holds an earlier localization.");
  if (!ap.parse(args)) return 0;
  if (!ap.has("map")) throw common::InputError("localize: --map MAP is required (a map.usmap or a run folder)");
  common::Stopwatch wall;
  const bool quiet = ap.flag("quiet");
  slam::LocalizationInfo info;
  info.input_path = ap.positional("LOG");
  info.map_path = slam::mapFilePath(ap.option("map"));
  if (ap.has("initial")) {
    info.initial_pose = parsePose(ap.option("initial"));
    info.initial_pose_given = true;
  }
  if (ap.has("separate-map")) info.separate_map = parseSeparateMap(ap.option("separate-map"));
  const bool smooth = !ap.flag("no-smoothing");
  // Without a named map or an initial pose (which is in the first map's frame), every map of the
  // file is searched.
  const bool search_maps = !ap.has("separate-map") && !info.initial_pose_given;
  std::vector<std::unique_ptr<slam::Pipeline>> separate;
  std::vector<std::unique_ptr<slam::Pipeline>> maps;
  maps.push_back(slam::loadMap(info.map_path, nullptr, info.separate_map > 0 || search_maps ? &separate : nullptr, slam::MapUse::Localize));
  if (info.separate_map > separate.size() && info.separate_map > 0)
    throw common::InputError("localize --separate-map " + std::to_string(info.separate_map) + ": " + info.map_path + " holds " +
                             std::to_string(separate.size()) + " separate map" + (separate.size() == 1 ? "" : "s"));
  if (info.separate_map > 0) {
    maps[0] = std::move(separate[info.separate_map - 1]);
  } else if (search_maps) {
    for (auto& p : separate) maps.push_back(std::move(p));
  }
  separate.clear();
  for (size_t k = 0; k < maps.size(); ++k) {
    // The final estimates of the map's keyframes (what `run` wrote out); nothing is added after.
    maps[k]->finish();
    if (maps[k]->keyframes().empty())
      throw common::InputError(info.map_path + ": " + (k == 0 && info.separate_map == 0 ? "the map" : "a separate map") +
                               " has no keyframes");
  }
  std::unique_ptr<io::DataSource> source = io::openDataSource(info.input_path);
  info.input_format = source->format();

  std::vector<std::unique_ptr<slam::Localizer>> localizers;
  std::vector<slam::Localizer*> running;
  for (const auto& p : maps) {
    localizers.push_back(std::make_unique<slam::Localizer>(p->map(), p->options(), slam::localizerOptions(p->options())));
    running.push_back(localizers.back().get());
  }
  if (info.initial_pose_given) localizers[0]->setInitialPose(info.initial_pose);
  common::ProgressBar bar("localize", 1000, !quiet);
  size_t shown_scans = 0, shown_fixes = 0;
  slam::MapsLocalization result = slam::localizeInMaps(
      running, *source,
      [&](const slam::LocalizedScan& r, double progress) {
        ++shown_scans;
        shown_fixes += r.relocalised;
        bar.update(static_cast<uint64_t>(progress * 1000), std::to_string(shown_scans) + " scans, " + slam::stateName(r.state) + ", " +
                                                               std::to_string(shown_fixes) + " relocalisations");
      },
      smooth ? &maps[0]->options() : nullptr);
  bar.finish();
  const slam::Localizer& localizer = *localizers[result.map];
  const std::vector<slam::LocalizedScan>& scans = result.scans;
  if (search_maps) {
    info.separate_map = result.map;
    info.maps_searched = maps.size();
  }
  if (scans.empty()) throw common::InputError(info.input_path + ": no laser scans the map's [input] options accept: nothing to localize");
  info.wall_s = wall.seconds();
  const std::string out = ap.option("out");
  info.smoothed = !result.smoothed.empty();
  const common::Json stats = slam::writeLocalizationOutputs(scans, result.smoothed, localizer.stats(), info, out);
  if (ap.flag("json")) std::cout << stats.dump() << "\n";
  if (!quiet) {
    const auto& s = localizer.stats();
    std::cerr << "urbanslam localize: " << s.scans_used << " scans, " << s.tracking << " tracked, " << s.lost << " lost (" << s.lost_s
              << " s), " << s.relocalisations << " relocalisations in " << info.wall_s << " s ("
              << stats.at("timing").at("real_time_factor").asNumber() << "x real time)";
    if (info.maps_searched > 1)
      std::cerr << "; searched in the file's " << info.maps_searched << " maps, "
                << (info.separate_map == 0 ? std::string("the first") : "separate map " + std::to_string(info.separate_map)) << " went on";
    std::cerr << "\n"
              << "outputs in " << std::filesystem::absolute(out).string() << "/ (trajectory_scans.tum, localization.csv, stats.json)\n";
  }
  return 0;
}

}  // namespace urbanslam::cli
