// The outputs MRPT writes for us: .simplemap (RawLogViewer, observations2map and MRPT's
// localisation apps read it; `eval` reads it back for the keyframe scans) and the occupancy grid PNG.
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "MrptConversions.h"
#include "OccupancyGridMrpt.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io {

namespace {

// A CSimpleMap whose entries are made as they are written: MRPT's serialisation of CSimpleMap
// (version 1: the entry count, then each entry's pose PDF and sensory frame as objects), one
// keyframe at a time, so that the output never holds every keyframe's MRPT observation (a few KB
// each) at once. It is read back as an ordinary CSimpleMap.
class StreamedSimpleMap : public mrpt::maps::CSimpleMap {
 public:
  explicit StreamedSimpleMap(const std::vector<PosedScan>& scans) : scans_(scans) {}

 protected:
  uint8_t serializeGetVersion() const override { return 1; }
  void serializeTo(mrpt::serialization::CArchive& out) const override {
    out.WriteAs<uint32_t>(scans_.size());
    LaserScan buffer;
    for (const auto& ps : scans_) {
      mrpt::poses::CPose3DPDFGaussian pose;
      pose.mean = mrpt::poses::CPose3D(ps.pose.x, ps.pose.y, 0, ps.pose.phi, 0, 0);
      mrpt::obs::CSensoryFrame sf;
      sf.insert(detail::toMrptScan(ps.get(buffer)));
      out << pose << sf;
    }
  }

 private:
  const std::vector<PosedScan>& scans_;
};

}  // namespace

void writeSimpleMap(const std::string& path, const std::vector<PosedScan>& scans) {
  const StreamedSimpleMap sm(scans);
  common::writeAtomically(path, [&](const std::string& tmp) {
    if (!sm.saveToFile(tmp)) throw common::InputError(path + ": cannot write");
  });
}

std::vector<KeyframeScan> readSimpleMap(const std::string& path) {
  mrpt::maps::CSimpleMap sm;
  bool ok = false;
  try {
    ok = sm.loadFromFile(path);
  } catch (const std::exception& e) {
    throw common::InputError(path + ": not a readable .simplemap (" + e.what() + ")");
  }
  if (!ok) throw common::InputError(path + ": cannot read the .simplemap");
  std::vector<KeyframeScan> out(sm.size());
  for (size_t i = 0; i < sm.size(); ++i) {
    const auto [pdf, sf] = sm.get(i);
    if (pdf) {
      const mrpt::poses::CPose3D p = pdf->getMeanVal();
      out[i].pose = {p.x(), p.y(), p.yaw()};
    }
    const auto obs = sf ? sf->getObservationByClass<mrpt::obs::CObservation2DRangeScan>() : nullptr;
    // A keyframe without returns was written as an empty scan: keep it empty, not an error.
    if (obs && obs->getScanSize() > 0) out[i].scan = detail::fromMrptScan(*obs, path + ": entry " + std::to_string(i));
  }
  return out;
}

std::pair<int, int> writeOccupancyGrid(const std::string& prefix, const std::vector<PosedScan>& scans, const OccupancyGridOptions& options,
                                       double* resolution_used) {
  // Bounds first, so the grid is allocated once instead of growing scan by scan (the points
  // scan by scan: the whole cloud is not needed for its bounds).
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  bool first = true;
  forEachMapPoint(scans, 1, [&](const std::vector<MapPoint>& pts) {
    for (const auto& p : pts) {
      if (first) {
        x0 = x1 = p.x;
        y0 = y1 = p.y;
        first = false;
      }
      x0 = std::min<double>(x0, p.x);
      x1 = std::max<double>(x1, p.x);
      y0 = std::min<double>(y0, p.y);
      y1 = std::max<double>(y1, p.y);
    }
  });
  for (const auto& ps : scans) {
    x0 = std::min(x0, ps.pose.x);
    x1 = std::max(x1, ps.pose.x);
    y0 = std::min(y0, ps.pose.y);
    y1 = std::max(y1, ps.pose.y);
  }
  const double margin = 1.0;
  const double width_m = x1 - x0 + 2 * margin, height_m = y1 - y0 + 2 * margin;
  double resolution = options.resolution_m;
  // Cells as MRPT counts them (rounded up, one extra per side), grown by 1% steps until they fit.
  const auto cells = [&](double r) { return (std::ceil(width_m / r) + 1) * (std::ceil(height_m / r) + 1); };
  if (cells(resolution) > options.max_cells) {
    resolution = std::max(resolution, std::sqrt(width_m * height_m / options.max_cells));
    while (cells(resolution) > options.max_cells) resolution *= 1.01;
  }
  if (resolution_used) *resolution_used = resolution;
  mrpt::maps::COccupancyGridMap2D grid(static_cast<float>(x0 - margin), static_cast<float>(x1 + margin), static_cast<float>(y0 - margin),
                                       static_cast<float>(y1 + margin), static_cast<float>(resolution));
  detail::configureGridInsertion(grid);
  LaserScan buffer;
  for (const auto& ps : scans) {
    const auto obs = detail::toMrptScan(ps.get(buffer));
    const mrpt::poses::CPose3D robot(ps.pose.x, ps.pose.y, 0, ps.pose.phi, 0, 0);
    grid.insertObservation(*obs, robot);
  }
  common::writeAtomically(prefix + ".png", [&](const std::string& tmp) {
    if (!grid.saveAsBitmapFile(tmp)) throw common::InputError(prefix + ".png: cannot write");
  });
  const std::string image = std::filesystem::path(prefix).filename().string() + ".png";
  detail::writeMapServerYaml(prefix + ".yaml", image, grid.getResolution(), grid.getXMin(), grid.getYMin(), options);
  return {static_cast<int>(grid.getSizeX()), static_cast<int>(grid.getSizeY())};
}

}  // namespace urbanslam::io
