#pragma once
// What `urbanslam localize` writes into its folder, as one unit (common::AtomicFolder: the
// folder appears complete or not at all; an existing folder that is neither empty nor an earlier
// localization's is refused, never deleted):
//   trajectory_scans.tum  the tracked scans' poses (what `urbanslam eval --relations` scores; lost
//                         scans have no trusted pose and are left out): smoothed, given the whole
//                         log (LocalizationSmoothing.h), when the run smoothed it, else as
//                         tracked; trajectory_odometry.tum holds the same poses, for eval, which
//                         reads both;
//   trajectory_online.tum the same scans' poses as the localizer gave them at each scan, from the
//                         log up to it (what a vehicle would have known then);
//   localization.csv      every scan: time, pose, covariance upper triangle, state (online);
//   stats.json            counts, time lost, relocalisations, wall time, real-time factor.
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/slam/Localizer.h"

namespace urbanslam::slam {

// The first line of localization.csv (it marks a folder as a localization's).
extern const char* const kLocalizationCsvHeader;

struct LocalizationInfo {
  std::string map_path, input_path, input_format;
  size_t separate_map = 0;   // which of the file's maps: 0 the first, k its k-th separate map (MapFile.h)
  size_t maps_searched = 1;  // the file's maps the log was searched in (LocalizeInMaps.h) when none was named
  bool initial_pose_given = false;
  common::Pose2 initial_pose;
  double wall_s = 0;      // the whole run: reading the map and the log included
  bool smoothed = false;  // trajectory_scans.tum is the smoothed trajectory
};

// stats.json's content (also what --json prints).
common::Json localizationStats(const std::vector<LocalizedScan>& scans, const LocalizerStats& stats, const LocalizationInfo& info);

// Writes the folder; returns the stats.json content written. `smoothed`: the smoothed pose of
// each of `scans`, or empty.
common::Json writeLocalizationOutputs(const std::vector<LocalizedScan>& scans, const std::vector<common::Pose2>& smoothed,
                                      const LocalizerStats& stats, const LocalizationInfo& info, const std::string& dir);

}  // namespace urbanslam::slam
