#pragma once
// The map products of a run, all built from scans placed at (estimated) vehicle poses:
// trajectory (TUM), point cloud (PLY binary/ASCII, PCD, XYZ), MRPT .simplemap, and an occupancy
// grid as PNG + YAML (ROS map_server convention). Every writer writes atomically.
#include <functional>
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/CompactScan.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/io/PointMask.h"
#include "urbanslam/io/ScanStore.h"

namespace urbanslam::io {

struct StampedPose {
  double timestamp = 0;
  common::Pose2 pose;
};

// A scan and the vehicle pose it was taken from: a LaserScan, a CompactScan, or a scan store's
// entry (a map's keyframes), which the writers expand one at a time, never all at once.
struct PosedScan {
  common::Pose2 pose;
  const LaserScan* scan = nullptr;
  const CompactScan* compact = nullptr;  // used when scan is null
  const ScanStore* store = nullptr;      // used when both are null: its scan `id`
  size_t id = 0;
  // The scan itself, or the compact or stored one expanded into `buffer`.
  const LaserScan& get(LaserScan& buffer) const;
  size_t validCount() const;  // without expanding
};

struct MapPoint {
  float x = 0, y = 0, z = 0;
};

// TUM RGB-D format: "timestamp x y z qx qy qz qw", one pose per line (z = 0, yaw-only quaternion).
void writeTum(const std::string& path, const std::vector<StampedPose>& poses);
// Reads a TUM trajectory (2D part). Throws common::InputError naming file and line.
std::vector<StampedPose> readTum(const std::string& path);

// World-frame points of all valid beams, optionally keeping every `decimation`-th point. With a
// mask, only the points it keeps take part (decimation counts those).
std::vector<MapPoint> mapPoints(const std::vector<PosedScan>& scans, int decimation = 1, const PointMask* mask = nullptr);
// The same points one scan at a time, for writers that stream them (a city's cloud is tens of
// bytes a beam held whole): `visit` gets each scan's points. Returns how many there were.
size_t forEachMapPoint(const std::vector<PosedScan>& scans, int decimation, const std::function<void(const std::vector<MapPoint>&)>& visit,
                       const PointMask* mask = nullptr);
// How many points mapPoints would give, without building them.
size_t countMapPoints(const std::vector<PosedScan>& scans, int decimation = 1, const PointMask* mask = nullptr);

enum class PlyEncoding { Ascii, BinaryLittleEndian };
void writePly(const std::string& path, const std::vector<MapPoint>& pts, PlyEncoding encoding);
void writePcd(const std::string& path, const std::vector<MapPoint>& pts);  // PCD v0.7, binary (as PCL writes it)
void writeXyz(const std::string& path, const std::vector<MapPoint>& pts);  // "x y z" per line
// The same files for mapPoints(scans, decimation, mask), streamed scan by scan.
void writePly(const std::string& path, const std::vector<PosedScan>& scans, int decimation, PlyEncoding encoding,
              const PointMask* mask = nullptr);
void writePcd(const std::string& path, const std::vector<PosedScan>& scans, int decimation, const PointMask* mask = nullptr);
void writeXyz(const std::string& path, const std::vector<PosedScan>& scans, int decimation, const PointMask* mask = nullptr);
// The points of a PLY file as writePly writes them (x, y, z floats, binary little-endian or
// ASCII). Throws common::InputError naming the file.
std::vector<MapPoint> readPly(const std::string& path);

// MRPT CSimpleMap: one (pose, sensory frame with the scan) per keyframe.
void writeSimpleMap(const std::string& path, const std::vector<PosedScan>& scans);
// Reads it back: the scan of each entry, in order (an entry without a 2D scan gives an empty
// one), and its pose. Throws common::InputError naming the file.
struct KeyframeScan {
  common::Pose2 pose;
  LaserScan scan;
};
std::vector<KeyframeScan> readSimpleMap(const std::string& path);

// A grid cell is reached this far from the sensor at most (MRPT's maxDistanceInsertion).
constexpr double kGridInsertionRangeM = 80.0;

struct OccupancyGridOptions {
  double resolution_m = 0.05;
  double occupied_thresh = 0.65;  // map_server thresholds, written into the YAML
  double free_thresh = 0.196;
  // Bounds the grid's memory (a few bytes per cell while it is built and written): a map
  // larger than this many cells at resolution_m (10^8: 500 m x 500 m at 5 cm) is written with
  // cells coarse enough to fit. A log whose odometry jumps kilometres would otherwise ask for
  // tens of gigabytes.
  double max_cells = 1e8;
};

// Writes `<prefix>.png` and `<prefix>.yaml`; returns the PNG's size in cells (width, height).
// `resolution_used` (optional) receives the cell size written, resolution_m unless the map
// needed more than max_cells.
std::pair<int, int> writeOccupancyGrid(const std::string& prefix, const std::vector<PosedScan>& scans, const OccupancyGridOptions& options,
                                       double* resolution_used = nullptr);

}  // namespace urbanslam::io
