// Point-cloud files written by hand: MRPT's PCD writer needs PCL (not in the dependency set)
// and its PLY writer adds an empty face element; these are the plain forms every viewer
// (CloudCompare, MeshLab, Open3D, PCL) reads.
#include <cmath>
#include <cstdio>
#include <cstring>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io {

std::vector<MapPoint> mapPoints(const std::vector<PosedScan>& scans, int decimation) {
  std::vector<MapPoint> pts;
  size_t k = 0;
  const size_t step = decimation < 1 ? 1 : static_cast<size_t>(decimation);
  for (const auto& ps : scans) {
    const double c = std::cos(ps.pose.phi), s = std::sin(ps.pose.phi);
    for (const auto& p : scanToPoints(*ps.scan, true)) {
      if (k++ % step) continue;
      pts.push_back({static_cast<float>(ps.pose.x + c * p.x - s * p.y), static_cast<float>(ps.pose.y + s * p.x + c * p.y), 0.f});
    }
  }
  return pts;
}

void writePly(const std::string& path, const std::vector<MapPoint>& pts, PlyEncoding encoding) {
  const bool binary = encoding == PlyEncoding::BinaryLittleEndian;
  common::AtomicFile f(path, binary);
  auto& os = f.stream();
  os << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
     << "comment urbanslam map\nelement vertex " << pts.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  if (binary) {
    static_assert(sizeof(MapPoint) == 12, "MapPoint must be three packed floats");
    // x86-64 is little-endian, as the header says.
    os.write(reinterpret_cast<const char*>(pts.data()), static_cast<std::streamsize>(pts.size() * sizeof(MapPoint)));
  } else {
    char buf[96];
    for (const auto& p : pts) {
      std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f\n", p.x, p.y, p.z);
      os << buf;
    }
  }
  f.commit();
}

void writePcd(const std::string& path, const std::vector<MapPoint>& pts) {
  common::AtomicFile f(path);
  auto& os = f.stream();
  os << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
     << "TYPE F F F\nCOUNT 1 1 1\nWIDTH " << pts.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << pts.size() << "\nDATA ascii\n";
  char buf[96];
  for (const auto& p : pts) {
    std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f\n", p.x, p.y, p.z);
    os << buf;
  }
  f.commit();
}

void writeXyz(const std::string& path, const std::vector<MapPoint>& pts) {
  common::AtomicFile f(path);
  auto& os = f.stream();
  char buf[96];
  for (const auto& p : pts) {
    std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f\n", p.x, p.y, p.z);
    os << buf;
  }
  f.commit();
}

}  // namespace urbanslam::io
