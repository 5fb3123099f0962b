#include "urbanslam/esdf/PoseGraphIO.h"

#include <zlib.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::esdf {
namespace {

std::string readWholeFile(const std::string& path) {
  // gzopen reads plain files transparently, so .gz and plain text share one path.
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw common::InputError(path + ": cannot open pose graph file");
  std::string out;
  char buf[1 << 16];
  int n;
  while ((n = gzread(f, buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  int err = 0;
  const char* msg = gzerror(f, &err);
  const bool bad = n < 0 || (err != Z_OK && err != Z_STREAM_END);
  const std::string what = msg ? msg : "";
  gzclose(f);
  if (bad) throw common::InputError(path + ": read error (" + what + "): truncated or corrupt file?");
  return out;
}

// Parses whitespace-separated numbers strictly (no trailing junk inside a token).
bool parseNumbers(std::istringstream& in, double* out, int count) {
  std::string tok;
  for (int k = 0; k < count; ++k) {
    if (!(in >> tok)) return false;
    char* end = nullptr;
    errno = 0;
    out[k] = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(out[k])) return false;
  }
  return true;
}

bool parseId(std::istringstream& in, long* id) {
  std::string tok;
  if (!(in >> tok)) return false;
  char* end = nullptr;
  *id = std::strtol(tok.c_str(), &end, 10);
  return end != tok.c_str() && *end == '\0' && *id >= 0;
}

}  // namespace

PoseGraph parsePoseGraph(const std::string& text, const std::string& name) {
  PoseGraph g;
  bool seen_g2o = false, seen_toro = false;
  std::istringstream lines(text);
  std::string line;
  long lineno = 0;
  auto fail = [&](const std::string& what) {
    throw common::InputError(name + ":" + std::to_string(lineno) + ": " + what);
  };
  while (std::getline(lines, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream in(line);
    std::string tag;
    if (!(in >> tag) || tag[0] == '#') continue;
    if (tag == "VERTEX_SE2" || tag == "VERTEX2") {
      (tag == "VERTEX2" ? seen_toro : seen_g2o) = true;
      PoseGraphVertex v;
      double p[3];
      if (!parseId(in, &v.id) || !parseNumbers(in, p, 3)) fail("malformed " + tag + " line (want: id x y theta)");
      v.pose = {p[0], p[1], p[2]};
      g.vertices.push_back(v);
    } else if (tag == "EDGE_SE2" || tag == "EDGE2") {
      const bool toro = tag == "EDGE2";
      (toro ? seen_toro : seen_g2o) = true;
      PoseGraphEdge e;
      double p[9];
      if (!parseId(in, &e.from) || !parseId(in, &e.to) || !parseNumbers(in, p, 9))
        fail("malformed " + tag + " line (want: from to dx dy dtheta and 6 information entries)");
      std::string extra;
      if (in >> extra) fail("trailing data on " + tag + " line");
      if (e.from == e.to) fail("edge from a vertex to itself");
      e.measurement = {p[0], p[1], p[2]};
      // g2o: upper triangle row-major, i11 i12 i13 i22 i23 i33. TORO: ff fs ss rr fr sr.
      double xx, xy, xt, yy, yt, tt;
      if (toro) {
        xx = p[3]; xy = p[4]; yy = p[5]; tt = p[6]; xt = p[7]; yt = p[8];
      } else {
        xx = p[3]; xy = p[4]; xt = p[5]; yy = p[6]; yt = p[7]; tt = p[8];
      }
      e.information << xx, xy, xt, xy, yy, yt, xt, yt, tt;
      // A singular or indefinite information matrix would make Lambda singular far from here.
      if (!(xx > 0 && yy > 0 && tt > 0) || Eigen::LLT<Mat3>(e.information).info() != Eigen::Success)
        fail("information matrix is not positive definite");
      g.edges.push_back(e);
    } else {
      // Other tags (FIX, VERTEX_XY landmarks, parameters) carry nothing for a pose graph.
      continue;
    }
  }
  if (g.edges.empty() && g.vertices.empty()) throw common::InputError(name + ": no VERTEX/EDGE lines: not a 2D pose graph");
  g.format = seen_toro && !seen_g2o ? PoseGraphFormat::Toro : PoseGraphFormat::G2o;
  return g;
}

PoseGraph readPoseGraph(const std::string& path) { return parsePoseGraph(readWholeFile(path), path); }

std::string formatPoseGraph(const PoseGraph& g, PoseGraphFormat format) {
  std::string out;
  char buf[512];
  const bool toro = format == PoseGraphFormat::Toro;
  for (const auto& v : g.vertices) {
    std::snprintf(buf, sizeof buf, "%s %ld %.17g %.17g %.17g\n", toro ? "VERTEX2" : "VERTEX_SE2", v.id,
                  v.pose.x(), v.pose.y(), v.pose.z());
    out += buf;
  }
  for (const auto& e : g.edges) {
    const Mat3& i = e.information;
    if (toro)
      std::snprintf(buf, sizeof buf, "EDGE2 %ld %ld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", e.from,
                    e.to, e.measurement.x(), e.measurement.y(), e.measurement.z(), i(0, 0), i(0, 1), i(1, 1), i(2, 2),
                    i(0, 2), i(1, 2));
    else
      std::snprintf(buf, sizeof buf, "EDGE_SE2 %ld %ld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                    e.from, e.to, e.measurement.x(), e.measurement.y(), e.measurement.z(), i(0, 0), i(0, 1), i(0, 2),
                    i(1, 1), i(1, 2), i(2, 2));
    out += buf;
  }
  return out;
}

void writePoseGraph(const PoseGraph& g, const std::string& path, PoseGraphFormat format) {
  common::AtomicFile f(path);
  f.stream() << formatPoseGraph(g, format);
  f.commit();
}

double poseGraphChi2(const PoseGraph& g, const std::vector<Vec3>& poses, const std::vector<long>& ids) {
  std::unordered_map<long, size_t> index;
  index.reserve(ids.size());
  for (size_t k = 0; k < ids.size(); ++k) index.emplace(ids[k], k);
  double chi2 = 0;
  for (const auto& e : g.edges) {
    const auto a = index.find(e.from), b = index.find(e.to);
    if (a == index.end() || b == index.end()) continue;
    const Vec3 err = relativePoseError(poses[a->second], poses[b->second], e.measurement);
    chi2 += err.dot(e.information * err);
  }
  return chi2;
}

}  // namespace urbanslam::esdf
