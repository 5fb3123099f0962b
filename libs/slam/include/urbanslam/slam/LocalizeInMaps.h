#pragma once
// Localization in a map file of several maps (the first map and its separate maps, MapFile.h,
// each in its own frame) when the user names none: every map's localizer takes the log from its
// first scan, side by side, until one of them finds its place (the first whose place search
// fixes the pose; at the same scan, the lower index wins); from then on that one goes on alone.
// Until then the others cost their place searches (while lost, each searches at most every few
// seconds of log time). A log found in none of the maps stays with the first, lost throughout.
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/LocalTrajectory.h"
#include "urbanslam/slam/Localizer.h"

namespace urbanslam::slam {

// One measurement at a time (a viewer steps it).
class MapsLocalizer {
 public:
  // `localizers`: one per map, none given an initial pose when there are several; a single one
  // simply localizes the whole log (it may have an initial pose). They must outlive this.
  // `smoothing_options` (optional): the maps' options, for local SLAM's trajectory of the log
  // (LocalTrajectory; one for all maps: it does not depend on them), which smoothed() needs.
  explicit MapsLocalizer(std::vector<Localizer*> localizers, const PipelineOptions* smoothing_options = nullptr);
  // The measurement to every localizer until one is chosen, then to that one. Returns the result
  // to show for it: the chosen localizer's (from the measurement at which it found its place),
  // before that the first localizer's; none for a measurement that is not a scan.
  std::optional<LocalizedScan> add(const io::Measurement& m);
  // The localizer that went on, or the first while none has found its place.
  size_t shown() const { return chosen_.value_or(0); }
  bool chosen() const { return chosen_.has_value(); }
  // Every result of localizer k so far, from the log's first scan.
  std::vector<LocalizedScan>& scans(size_t k) { return scans_.at(k); }
  // The smoothed pose of each of scans(k) (smoothLocalization); empty without smoothing options
  // or without any fix.
  std::vector<common::Pose2> smoothed(size_t k) const;

 private:
  std::vector<Localizer*> localizers_;
  std::unique_ptr<LocalTrajectory> trajectory_;  // on the heap: the localizers keep its address
  double fix_covariance_scale_ = 1, fix_spacing_m_ = 0;
  std::vector<std::vector<LocalizedScan>> scans_;
  std::optional<size_t> chosen_;
};

struct MapsLocalization {
  size_t map = 0;                       // the localizer that went on (an index into the localizers)
  std::vector<LocalizedScan> scans;     // its results, from the first scan
  std::vector<common::Pose2> smoothed;  // the smoothed pose of each (empty: not smoothed)
};

// The whole log through a MapsLocalizer. on_scan (optional) sees each result it shows, with the
// source's progress. With `smoothing_options`, the trajectory is smoothed as well.
MapsLocalization localizeInMaps(const std::vector<Localizer*>& localizers, io::DataSource& source,
                                const std::function<void(const LocalizedScan&, double progress)>& on_scan = {},
                                const PipelineOptions* smoothing_options = nullptr);

}  // namespace urbanslam::slam
