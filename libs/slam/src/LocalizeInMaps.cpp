#include "urbanslam/slam/LocalizeInMaps.h"

#include <stdexcept>

namespace urbanslam::slam {

MapsLocalizer::MapsLocalizer(std::vector<Localizer*> localizers) : localizers_(std::move(localizers)), scans_(localizers_.size()) {
  if (localizers_.empty()) throw std::invalid_argument("MapsLocalizer: no localizer");
  if (localizers_.size() == 1) chosen_ = 0;
}

std::optional<LocalizedScan> MapsLocalizer::add(const io::Measurement& m) {
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
                                const std::function<void(const LocalizedScan&, double progress)>& on_scan) {
  MapsLocalizer maps(localizers);
  io::Measurement m;
  while (source.next(m))
    if (auto r = maps.add(m); r && on_scan) on_scan(*r, source.progress());
  const size_t k = maps.shown();
  return {k, std::move(maps.scans(k))};
}

}  // namespace urbanslam::slam
