// Point-cloud files written by hand: MRPT's PCD writer needs PCL (not in the dependency set)
// and its PLY writer adds an empty face element; these are the plain forms every viewer
// (CloudCompare, MeshLab, Open3D, PCL) reads. Each is written from a whole cloud or streamed
// from the posed scans, one scan's points at a time (the count in the header comes first, from
// the validity flags).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <ostream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::io {

namespace {

size_t decimationStep(int decimation) { return decimation < 1 ? 1 : static_cast<size_t>(decimation); }

// A cloud's points to a file in pieces: the whole cloud is one piece, a streamed map one per scan.
using PointsSource = std::function<void(const std::function<void(const std::vector<MapPoint>&)>&)>;

void writeXyzLines(std::ostream& os, const PointsSource& points) {
  points([&](const std::vector<MapPoint>& pts) {
    char buf[96];
    for (const auto& p : pts) {
      std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f\n", p.x, p.y, p.z);
      os << buf;
    }
  });
}

// Three little-endian floats per point: the body of binary PLY and binary PCD.
void writePackedPoints(std::ostream& os, const PointsSource& points) {
  points([&](const std::vector<MapPoint>& pts) {
    static_assert(sizeof(MapPoint) == 12, "MapPoint must be three packed floats");
    // x86-64 is little-endian, as the headers say.
    os.write(reinterpret_cast<const char*>(pts.data()), static_cast<std::streamsize>(pts.size() * sizeof(MapPoint)));
  });
}

void writePlyBody(std::ostream& os, size_t count, PlyEncoding encoding, const PointsSource& points) {
  const bool binary = encoding == PlyEncoding::BinaryLittleEndian;
  os << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
     << "comment urbanslam map\nelement vertex " << count << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  if (!binary) {
    writeXyzLines(os, points);  // ASCII PLY's vertex lines are XYZ lines
    return;
  }
  writePackedPoints(os, points);
}

// Binary, as PCL's savePCDFileBinary writes it (x y z floats per point, little-endian): a city's
// cloud in ASCII took seconds of number formatting and twice the bytes.
void writePcdBody(std::ostream& os, size_t count, const PointsSource& points) {
  os << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
     << "TYPE F F F\nCOUNT 1 1 1\nWIDTH " << count << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << count << "\nDATA binary\n";
  writePackedPoints(os, points);
}

PointsSource whole(const std::vector<MapPoint>& pts) {
  return [&pts](const std::function<void(const std::vector<MapPoint>&)>& visit) { visit(pts); };
}

PointsSource streamed(const std::vector<PosedScan>& scans, int decimation, const PointMask* mask) {
  return [&scans, decimation, mask](const std::function<void(const std::vector<MapPoint>&)>& visit) {
    forEachMapPoint(scans, decimation, visit, mask);
  };
}

}  // namespace

const LaserScan& PosedScan::get(LaserScan& buffer) const {
  if (scan) return *scan;
  if (compact)
    compact->expandInto(buffer);
  else if (store)
    store->expandInto(id, buffer);
  else
    buffer = LaserScan{};
  return buffer;
}

size_t PosedScan::validCount() const {
  return scan ? scan->validCount() : compact ? compact->validCount() : store ? store->validCount(id) : 0;
}

size_t forEachMapPoint(const std::vector<PosedScan>& scans, int decimation, const std::function<void(const std::vector<MapPoint>&)>& visit,
                       const PointMask* mask) {
  const size_t step = decimationStep(decimation);
  size_t point = 0, k = 0, n = 0;
  LaserScan buffer;
  std::vector<MapPoint> pts;
  for (const auto& ps : scans) {
    const double c = std::cos(ps.pose.phi), s = std::sin(ps.pose.phi);
    pts.clear();
    for (const auto& p : scanToPoints(ps.get(buffer), true)) {
      if (mask && !mask->keeps(point++)) continue;
      if (k++ % step) continue;
      pts.push_back({static_cast<float>(ps.pose.x + c * p.x - s * p.y), static_cast<float>(ps.pose.y + s * p.x + c * p.y), 0.f});
    }
    n += pts.size();
    if (!pts.empty()) visit(pts);
  }
  return n;
}

size_t countMapPoints(const std::vector<PosedScan>& scans, int decimation, const PointMask* mask) {
  size_t valid = 0;
  for (const auto& ps : scans) valid += ps.validCount();
  if (mask) valid = mask->kept() + (valid > mask->size() ? valid - mask->size() : 0);
  // Points k = 0, step, 2 step, ... of the valid beams in order.
  const size_t step = decimationStep(decimation);
  return (valid + step - 1) / step;
}

std::vector<MapPoint> mapPoints(const std::vector<PosedScan>& scans, int decimation, const PointMask* mask) {
  std::vector<MapPoint> out;
  out.reserve(countMapPoints(scans, decimation, mask));
  forEachMapPoint(
      scans, decimation, [&](const std::vector<MapPoint>& pts) { out.insert(out.end(), pts.begin(), pts.end()); }, mask);
  return out;
}

void writePly(const std::string& path, const std::vector<MapPoint>& pts, PlyEncoding encoding) {
  common::AtomicFile f(path, encoding == PlyEncoding::BinaryLittleEndian);
  writePlyBody(f.stream(), pts.size(), encoding, whole(pts));
  f.commit();
}

void writePly(const std::string& path, const std::vector<PosedScan>& scans, int decimation, PlyEncoding encoding, const PointMask* mask) {
  common::AtomicFile f(path, encoding == PlyEncoding::BinaryLittleEndian);
  writePlyBody(f.stream(), countMapPoints(scans, decimation, mask), encoding, streamed(scans, decimation, mask));
  f.commit();
}

void writePcd(const std::string& path, const std::vector<MapPoint>& pts) {
  common::AtomicFile f(path, true);
  writePcdBody(f.stream(), pts.size(), whole(pts));
  f.commit();
}

void writePcd(const std::string& path, const std::vector<PosedScan>& scans, int decimation, const PointMask* mask) {
  common::AtomicFile f(path, true);
  writePcdBody(f.stream(), countMapPoints(scans, decimation, mask), streamed(scans, decimation, mask));
  f.commit();
}

void writeXyz(const std::string& path, const std::vector<MapPoint>& pts) {
  common::AtomicFile f(path);
  writeXyzLines(f.stream(), whole(pts));
  f.commit();
}

void writeXyz(const std::string& path, const std::vector<PosedScan>& scans, int decimation, const PointMask* mask) {
  common::AtomicFile f(path);
  writeXyzLines(f.stream(), streamed(scans, decimation, mask));
  f.commit();
}

std::vector<MapPoint> readPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw common::InputError(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line != "ply") throw common::InputError(path + ": not a PLY file");
  bool binary = false, have_format = false;
  size_t count = 0;
  std::vector<std::string> properties;
  bool in_vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string f;
      ls >> f;
      if (f != "ascii" && f != "binary_little_endian") throw common::InputError(path + ": PLY format '" + f + "' is not read");
      binary = f == "binary_little_endian";
      have_format = true;
    } else if (word == "element") {
      std::string name;
      long long n = -1;
      ls >> name >> n;
      in_vertex = name == "vertex";
      if (in_vertex) {
        if (n < 0) throw common::InputError(path + ": bad vertex count");
        count = static_cast<size_t>(n);
      } else if (n != 0) {
        throw common::InputError(path + ": element '" + name + "' is not read (only vertices)");
      }
    } else if (word == "property" && in_vertex) {
      std::string type, name;
      ls >> type >> name;
      if (type != "float") throw common::InputError(path + ": vertex property '" + name + "' is not a float");
      properties.push_back(name);
    }
  }
  if (line != "end_header" || !have_format) throw common::InputError(path + ": PLY header incomplete");
  if (properties != std::vector<std::string>{"x", "y", "z"}) throw common::InputError(path + ": vertices are not (x, y, z)");
  std::vector<MapPoint> out;
  // Not reserved from the header's count: a corrupt count must not allocate gigabytes.
  for (size_t i = 0; i < count; ++i) {
    MapPoint p;
    if (binary ? !in.read(reinterpret_cast<char*>(&p), sizeof p) : !(in >> p.x >> p.y >> p.z))
      throw common::InputError(path + ": truncated after " + std::to_string(i) + " of " + std::to_string(count) + " vertices");
    out.push_back(p);
  }
  return out;
}

}  // namespace urbanslam::io
