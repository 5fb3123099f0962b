#include "urbanslam/slam/LocalizeInMaps.h"

#include <optional>
#include <stdexcept>

namespace urbanslam::slam {

MapsLocalization localizeInMaps(const std::vector<Localizer*>& localizers, io::DataSource& source,
                                const std::function<void(const LocalizedScan&, double progress)>& on_scan) {
  if (localizers.empty()) throw std::invalid_argument("localizeInMaps: no localizer");
  std::vector<std::vector<LocalizedScan>> scans(localizers.size());
  std::optional<size_t> chosen;
  if (localizers.size() == 1) chosen = 0;
  io::Measurement m;
  while (source.next(m)) {
    if (chosen) {
      if (auto r = localizers[*chosen]->add(m)) {
        scans[*chosen].push_back(*r);
        if (on_scan) on_scan(*r, source.progress());
      }
      continue;
    }
    // Every localizer takes the measurement (their maps' input options may differ: each keeps
    // the scans it used). Shown: the first localizer's result until one finds its place.
    std::optional<size_t> found;
    std::optional<LocalizedScan> first;
    for (size_t k = 0; k < localizers.size(); ++k) {
      if (auto r = localizers[k]->add(m)) {
        if (!found && r->state == LocalizationState::Tracking) found = k;
        if (k == 0) first = *r;
        scans[k].push_back(std::move(*r));
      }
    }
    chosen = found;
    if (on_scan && (found || first)) on_scan(found ? scans[*found].back() : *first, source.progress());
  }
  const size_t k = chosen.value_or(0);
  return {k, std::move(scans[k])};
}

}  // namespace urbanslam::slam
