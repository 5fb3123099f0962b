#include "urbanslam/slam/LocalizeInMaps.h"

#include <stdexcept>

#include "urbanslam/slam/LocalizationSmoothing.h"

namespace urbanslam::slam {

MapsLocalizer::MapsLocalizer(std::vector<Localizer*> localizers, const PipelineOptions* smoothing_options)
    : localizers_(std::move(localizers)), scans_(localizers_.size()) {
  if (localizers_.empty()) throw std::invalid_argument("MapsLocalizer: no localizer");
  if (localizers_.size() == 1) chosen_ = 0;
  if (smoothing_options) {
    trajectory_ = std::make_unique<LocalTrajectory>(*smoothing_options);
    for (Localizer* l : localizers_) l->followLocalTrajectory(trajectory_.get());
    fix_covariance_scale_ = smoothing_options->local.covariance_scale;
    fix_spacing_m_ = smoothing_options->keyframes.min_translation_m;
  }
}

std::vector<common::Pose2> MapsLocalizer::smoothed(size_t k) const {
  if (!trajectory_) return {};
  return smoothLocalization(*trajectory_, scans_.at(k), fix_covariance_scale_, fix_spacing_m_);
}

std::optional<LocalizedScan> MapsLocalizer::add(const io::Measurement& m) {
  if (trajectory_) trajectory_->add(m);
  if (chosen_) {
    auto r = localizers_[*chosen_]->add(m);
    if (r) scans_[*chosen_].push_back(*r);
    return r;
  }
  // Every localizer takes the measurement (their maps' input options may differ: each keeps the
  // scans it used). Shown: the first localizer's result until one finds its place.
  std::optional<size_t> found;
  std::optional<LocalizedScan> first;
  for (size_t k = 0; k < localizers_.size(); ++k) {
    if (auto r = localizers_[k]->add(m)) {
      if (!found && r->state == LocalizationState::Tracking) found = k;
      if (k == 0) first = *r;
      scans_[k].push_back(std::move(*r));
    }
  }
  chosen_ = found;
  if (found) return scans_[*found].back();
  return first;
}

MapsLocalization localizeInMaps(const std::vector<Localizer*>& localizers, io::DataSource& source,
                                const std::function<void(const LocalizedScan&, double progress)>& on_scan,
                                const PipelineOptions* smoothing_options) {
  MapsLocalizer maps(localizers, smoothing_options);
  io::Measurement m;
  while (source.next(m))
    if (auto r = maps.add(m); r && on_scan) on_scan(*r, source.progress());
  const size_t k = maps.shown();
  std::vector<common::Pose2> smoothed = maps.smoothed(k);
  return {k, std::move(maps.scans(k)), std::move(smoothed)};
}

}  // namespace urbanslam::slam
