#include "LocalizationWorker.h"

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/slam/MapFile.h"

namespace urbanslam::gui {

LocalizationWorker::LocalizationWorker(const std::string& map_path, const std::string& log_path)
    : map_path_(slam::mapFilePath(map_path)), log_path_(log_path) {
  std::vector<std::unique_ptr<slam::Pipeline>> separate;
  maps_.push_back(slam::loadMap(map_path_, nullptr, &separate, slam::MapUse::Localize));
  for (auto& p : separate) maps_.push_back(std::move(p));
  for (size_t k = 0; k < maps_.size(); ++k) {
    maps_[k]->finish();  // the final estimates of the map's keyframes, as `localize` uses them
    if (maps_[k]->keyframes().empty())
      throw common::InputError(map_path_ + ": " + (k == 0 ? "the map" : "a separate map") + " has no keyframes");
  }
  source_ = io::openDataSource(log_path);
  std::vector<slam::Localizer*> running;
  for (const auto& p : maps_) {
    localizers_.push_back(std::make_unique<slam::Localizer>(p->map(), p->options(), slam::localizerOptions(p->options())));
    running.push_back(localizers_.back().get());
  }
  // Following local SLAM's trajectory, as `urbanslam localize` does by default.
  localizer_ = std::make_unique<slam::MapsLocalizer>(running, &maps_[0]->options());
  state_.localizing = true;
  drawMap(0);
}

void LocalizationWorker::drawMap(size_t k) {
  const slam::Pipeline& map = *maps_[k];
  state_.keyframes.clear();
  for (const auto& kf : map.keyframes()) {
    auto pts = std::make_shared<const std::vector<io::Point2>>(kf.hasScan() ? io::scanToPoints(map.map().scan(kf.index), true)
                                                                            : std::vector<io::Point2>{});
    state_.keyframes.push_back({kf.index, kf.timestamp, kf.pose, std::move(pts), nullptr});
  }
  state_.stats.keyframes = state_.keyframes.size();
  // The poses shown so far were in the map drawn before, lost: they mean nothing in this one.
  state_.localized.clear();
  drawn_ = k;
  ++state_.version;
}

LocalizationWorker::~LocalizationWorker() { runner_.stop(); }

std::string LocalizationWorker::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

MapSnapshot LocalizationWorker::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

size_t LocalizationWorker::version() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_.version;
}

PacedRunner::Step LocalizationWorker::step() {
  // The localizer runs outside the lock: the GUI's snapshots never wait for a place search.
  PacedRunner::Step s;
  io::Measurement m;
  std::optional<slam::LocalizedScan> r;
  std::string failure;
  common::Stopwatch sw;
  try {
    s.more = source_->next(m);
    if (s.more) r = localizer_->add(m);
  } catch (const std::exception& e) {
    failure = e.what();
    s.more = false;
  }
  const double step_ms = sw.milliseconds();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!s.more) {
    if (!failure.empty() && error_.empty()) error_ = failure;
    if (failure.empty() && state_.stats.scans == 0 && error_.empty())
      error_ = log_path_ + ": no laser scans the map's [input] options accept: nothing to localize";
    state_.finished = true;
    ++state_.version;
    return s;
  }
  if (!r) return s;  // odometry: nothing to show, no pause
  if (localizer_->shown() != drawn_) drawMap(localizer_->shown());
  record(*r, step_ms);
  s.unit_done = true;
  s.paced = true;
  s.log_time = r->timestamp;
  return s;
}

void LocalizationWorker::record(const slam::LocalizedScan& r, double step_ms) {
  auto& s = state_.stats;
  if (first_timestamp_ < 0) first_timestamp_ = r.timestamp;
  ++s.scans;
  s.addStep(r.timestamp - first_timestamp_, step_ms, source_->progress());
  const bool tracking = r.state == slam::LocalizationState::Tracking;
  if (!tracking) ++state_.lost_scans;
  if (r.relocalised) ++state_.relocalisations;
  if (r.has_pose) {
    state_.localized.push_back({r.timestamp, r.pose, tracking});
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) state_.current_covariance[static_cast<size_t>(3 * i + j)] = r.cov(i, j);
  }
  ++state_.version;
}

}  // namespace urbanslam::gui
