#pragma once
// Localization in a map file of several maps (the first map and its separate maps, MapFile.h,
// each in its own frame) when the user names none: every map's localizer takes the log from its
// first scan, side by side, until one of them finds its place (the first whose place search
// fixes the pose; at the same scan, the lower index wins); from then on that one goes on alone.
// Until then the others cost their place searches (while lost, each searches at most every few
// seconds of log time). A log found in none of the maps stays with the first, lost throughout.
#include <functional>
#include <vector>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/Localizer.h"

namespace urbanslam::slam {

struct MapsLocalization {
  size_t map = 0;                    // the localizer that went on (an index into the localizers)
  std::vector<LocalizedScan> scans;  // its results, from the first scan
};

// `localizers`: one per map, none given an initial pose when there are several; a single one
// simply localizes the whole log (it may have an initial pose). on_scan (optional) sees each
// result of the first localizer until one is chosen, then the chosen one's, with the source's
// progress.
MapsLocalization localizeInMaps(const std::vector<Localizer*>& localizers, io::DataSource& source,
                                const std::function<void(const LocalizedScan&, double progress)>& on_scan = {});

}  // namespace urbanslam::slam
