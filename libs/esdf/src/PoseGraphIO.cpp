#include "urbanslam/esdf/PoseGraphIO.h"

#include <zlib.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string_view>
#include <unordered_map>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"

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

// Whitespace-separated tokens of one line, without copies (istringstream and strtod made
// reading ~10 % of a back-end run on the larger graphs).
class Tokens {
 public:
  explicit Tokens(std::string_view line) : rest_(line) {}
  bool next(std::string_view* tok) {
    size_t b = 0;
    while (b < rest_.size() && std::isspace(static_cast<unsigned char>(rest_[b]))) ++b;
    size_t e = b;
    while (e < rest_.size() && !std::isspace(static_cast<unsigned char>(rest_[e]))) ++e;
    *tok = rest_.substr(b, e - b);
    rest_ = rest_.substr(e);
    return !tok->empty();
  }

 private:
  std::string_view rest_;
};

// Parses numbers strictly (common::parseDecimal: decimal, finite, the whole token).
bool parseNumbers(Tokens& in, double* out, int count) {
  std::string_view tok;
  for (int k = 0; k < count; ++k) {
    if (!in.next(&tok)) return false;
    const auto v = common::parseDecimal(tok);
    if (!v) return false;
    out[k] = *v;
  }
  return true;
}

bool parseId(Tokens& in, long* id) {
  std::string_view tok;
  if (!in.next(&tok)) return false;
  const auto v = common::parseWholeNumber(tok);
  if (!v || *v < 0) return false;
  *id = *v;
  return true;
}

// The first of `count` values beyond max_abs, or -1.
int firstBeyond(const double* v, int count, double max_abs) {
  for (int k = 0; k < count; ++k)
    if (std::abs(v[k]) > max_abs) return k;
  return -1;
}

}  // namespace

constexpr double kMaxInformation = 1e12;

PoseGraph parsePoseGraph(const std::string& text, const std::string& name) {
  PoseGraph g;
  g.name = name;
  bool seen_g2o = false, seen_toro = false;
  std::string_view rest(text);
  long lineno = 0;
  auto fail = [&](const std::string& what) { throw common::InputError(name + ":" + std::to_string(lineno) + ": " + what); };
  while (!rest.empty()) {
    ++lineno;
    const size_t eol = std::min(rest.find('\n'), rest.size());
    const std::string_view line = rest.substr(0, eol);
    rest = rest.substr(std::min(eol + 1, rest.size()));
    Tokens in(line);  // '\r' of CRLF files is whitespace to the tokenizer
    std::string_view tag;
    if (!in.next(&tag) || tag[0] == '#') continue;
    if (tag == "VERTEX_SE2" || tag == "VERTEX2") {
      (tag == "VERTEX2" ? seen_toro : seen_g2o) = true;
      PoseGraphVertex v;
      double p[3];
      if (!parseId(in, &v.id) || !parseNumbers(in, p, 3)) fail("malformed " + std::string(tag) + " line (want: id x y theta)");
      if (firstBeyond(p, 3, common::kMaxCoordinate) >= 0) fail("vertex pose out of range (|value| > 1e7)");
      v.pose = {p[0], p[1], p[2]};
      g.vertices.push_back(v);
    } else if (tag == "EDGE_SE2" || tag == "EDGE2") {
      const bool toro = tag == "EDGE2";
      (toro ? seen_toro : seen_g2o) = true;
      PoseGraphEdge e;
      double p[9];
      if (!parseId(in, &e.from) || !parseId(in, &e.to) || !parseNumbers(in, p, 9))
        fail("malformed " + std::string(tag) + " line (want: from to dx dy dtheta and 6 information entries)");
      std::string_view extra;
      if (in.next(&extra)) fail("trailing data on " + std::string(tag) + " line");
      if (e.from == e.to) fail("edge from a vertex to itself");
      if (firstBeyond(p, 3, common::kMaxCoordinate) >= 0) fail("edge measurement out of range (|value| > 1e7)");
      // Information 1/sigma^2 beyond 1e12 (sigma < 1 micrometre) only adds rounding error: next
      // to the other factors such an entry leaves Lambda numerically singular.
      if (firstBeyond(p + 3, 6, kMaxInformation) >= 0) fail("information entry out of range (|value| > 1e12)");
      e.measurement = {p[0], p[1], p[2]};
      e.line = lineno;
      // g2o: upper triangle row-major, i11 i12 i13 i22 i23 i33. TORO: ff fs ss rr fr sr.
      double xx, xy, xt, yy, yt, tt;
      if (toro) {
        xx = p[3];
        xy = p[4];
        yy = p[5];
        tt = p[6];
        xt = p[7];
        yt = p[8];
      } else {
        xx = p[3];
        xy = p[4];
        xt = p[5];
        yy = p[6];
        yt = p[7];
        tt = p[8];
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
    std::snprintf(buf, sizeof buf, "%s %ld %.17g %.17g %.17g\n", toro ? "VERTEX2" : "VERTEX_SE2", v.id, v.pose.x(), v.pose.y(), v.pose.z());
    out += buf;
  }
  for (const auto& e : g.edges) {
    const Mat3& i = e.information;
    if (toro)
      std::snprintf(buf, sizeof buf, "EDGE2 %ld %ld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", e.from, e.to,
                    e.measurement.x(), e.measurement.y(), e.measurement.z(), i(0, 0), i(0, 1), i(1, 1), i(2, 2), i(0, 2), i(1, 2));
    else
      std::snprintf(buf, sizeof buf, "EDGE_SE2 %ld %ld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", e.from, e.to,
                    e.measurement.x(), e.measurement.y(), e.measurement.z(), i(0, 0), i(0, 1), i(0, 2), i(1, 1), i(1, 2), i(2, 2));
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
