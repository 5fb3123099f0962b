#include "urbanslam/slam/LocalizationOutputs.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/AtomicFolder.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::slam {

namespace fs = std::filesystem;

const char* const kLocalizationCsvHeader =
    "time,x,y,phi,cov_xx,cov_xy,cov_xphi,cov_yy,cov_yphi,cov_phiphi,state,matched_fraction,mahalanobis2";

namespace {

// An earlier localization's folder: its localization.csv says so.
bool isLocalizationFolder(const std::string& dir) {
  return common::isReplaceableOutputFolder(dir, "localization.csv",
                                           [](const std::string& first) { return first == kLocalizationCsvHeader; });
}

}  // namespace

common::Json localizationStats(const std::vector<LocalizedScan>& scans, const LocalizerStats& s, const LocalizationInfo& info) {
  using common::Json;
  Json j = Json::object();
  j["map"] = info.map_path;
  if (info.separate_map > 0) j["separate_map"] = info.separate_map;
  if (info.maps_searched > 1) j["maps_searched"] = info.maps_searched;
  j["input"] = info.input_path;
  j["input_format"] = info.input_format;
  if (info.initial_pose_given) {
    Json p = Json::array();
    for (double v : {info.initial_pose.x, info.initial_pose.y, info.initial_pose.phi}) p.push(v);
    j["initial_pose"] = std::move(p);
  } else {
    j["initial_pose"] = Json();
  }
  Json& c = j["counts"];
  c["measurements"] = s.measurements;
  c["scans"] = s.scans;
  c["scans_used"] = s.scans_used;
  c["odometry"] = s.odometry;
  c["tracking"] = s.tracking;
  c["lost"] = s.lost;
  c["matches_failed"] = s.matches_failed;
  c["matches_skipped"] = s.matches_skipped;
  c["lost_events"] = s.lost_events;
  c["place_searches"] = s.place_searches;
  c["relocalisations"] = s.relocalisations;
  c["fixes_rejected"] = s.fixes_rejected;
  c["discontinuities"] = s.discontinuities;
  c["poses_replaced"] = s.poses_replaced;
  c["place_search_windows"] = s.place_search_windows;
  c["places_followed"] = s.places_followed;
  c["places_decided"] = s.places_decided;
  c["images"] = s.images;
  c["image_place_searches"] = s.image_place_searches;
  c["image_relocalisations"] = s.image_relocalisations;
  c["map_references_built"] = s.references_built;
  c["coarse_grids_built"] = s.coarse_grids_built;
  Json& l = j["localization"];
  l["lost_s"] = s.lost_s;
  l["first_fix_s"] = s.first_fix_s >= 0 ? Json(s.first_fix_s) : Json();
  l["tracking_fraction"] = s.scans_used > 0 ? static_cast<double>(s.tracking) / static_cast<double>(s.scans_used) : 0.0;
  std::vector<double> sigma;
  for (const auto& r : scans)
    if (r.state == LocalizationState::Tracking) sigma.push_back(std::sqrt(std::max(0.0, r.cov(0, 0) + r.cov(1, 1))));
  l["position_sigma_m_p50"] = common::percentile(sigma, 50);
  l["position_sigma_m_p95"] = common::percentile(sigma, 95);
  l["smoothed"] = info.smoothed;
  Json& t = j["timing"];  // l is invalid from here: inserting into j may move its values
  const double duration = s.last_timestamp - s.first_timestamp;
  t["wall_s"] = info.wall_s;
  t["localizer_wall_s"] = s.wall_s;
  t["place_search_wall_s"] = s.place_search_wall_s;
  t["log_duration_s"] = duration;
  t["real_time_factor"] = info.wall_s > 0 ? duration / info.wall_s : 0.0;
  t["peak_rss_mb"] = static_cast<double>(common::peakResidentBytes()) / (1024.0 * 1024.0);
  return j;
}

common::Json writeLocalizationOutputs(const std::vector<LocalizedScan>& scans, const std::vector<common::Pose2>& smoothed,
                                      const LocalizerStats& stats, const LocalizationInfo& info, const std::string& dir) {
  if (!smoothed.empty() && smoothed.size() != scans.size())
    throw std::logic_error("writeLocalizationOutputs: smoothed poses do not match the scans");
  common::AtomicFolder folder(dir, isLocalizationFolder);
  const auto path = [&](const std::string& name) { return (fs::path(folder.stagingPath()) / name).string(); };
  std::vector<io::StampedPose> tracked, online;
  for (size_t i = 0; i < scans.size(); ++i) {
    const LocalizedScan& r = scans[i];
    if (r.state != LocalizationState::Tracking) continue;
    online.push_back({r.timestamp, r.pose});
    tracked.push_back({r.timestamp, smoothed.empty() ? r.pose : smoothed[i]});
  }
  io::writeTum(path("trajectory_scans.tum"), tracked);
  io::writeTum(path("trajectory_online.tum"), online);
  // `urbanslam eval` reads a run's trajectory at odometry times too; a localization has its
  // poses at the tracked scans only.
  io::writeTum(path("trajectory_odometry.tum"), tracked);
  {
    common::AtomicFile f(path("localization.csv"));
    f.stream() << kLocalizationCsvHeader << "\n";
    char buf[512];
    for (const auto& r : scans) {
      if (r.has_pose) {
        const Eigen::Matrix3d& c = r.cov;
        std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.6f,%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%s,%.4f,%.4g\n", r.timestamp, r.pose.x, r.pose.y,
                      r.pose.phi, c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2), c(2, 2), stateName(r.state), r.matched_fraction,
                      r.mahalanobis2);
      } else {
        std::snprintf(buf, sizeof buf, "%.6f,nan,nan,nan,nan,nan,nan,nan,nan,nan,%s,%.4f,%.4g\n", r.timestamp, stateName(r.state),
                      r.matched_fraction, r.mahalanobis2);
      }
      f.stream() << buf;
    }
    f.commit();
  }
  common::Json j = localizationStats(scans, stats, info);
  common::writeTextAtomically(path("stats.json"), j.dump(2) + "\n");
  folder.commit();
  return j;
}

}  // namespace urbanslam::slam
