#include "urbanslam/esdf/TrajectoryError.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"
#include "urbanslam/common/RigidFit.h"

namespace urbanslam::esdf {

TrajectoryError trajectoryError(const std::vector<PoseGraphVertex>& est, const std::vector<PoseGraphVertex>& ref) {
  std::unordered_map<long, const Vec3*> by_id;
  by_id.reserve(ref.size());
  for (const auto& v : ref) by_id.emplace(v.id, &v.pose);
  std::vector<std::pair<const Vec3*, const Vec3*>> pairs;  // (estimate, reference)
  pairs.reserve(est.size());
  for (const auto& v : est) {
    const auto it = by_id.find(v.id);
    if (it != by_id.end()) pairs.emplace_back(&v.pose, it->second);
  }
  if (pairs.size() < 2) throw common::InputError("trajectory error: fewer than two vertex ids in common with the reference");
  // The estimate rigidly aligned onto the reference (the project's one closed-form fit).
  std::vector<Eigen::Vector2d> src, dst;
  for (const auto& [p, q] : pairs) {
    src.push_back(p->head<2>());
    dst.push_back(q->head<2>());
  }
  common::Pose2 fit;
  if (!common::fitRigid2D(src, dst, {}, &fit)) throw common::InputError("trajectory error: the alignment onto the reference is not finite");
  const double theta = fit.phi;
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(theta).toRotationMatrix();
  const Eigen::Vector2d t(fit.x, fit.y);
  TrajectoryError out;
  out.matched = pairs.size();
  out.alignment = {t.x(), t.y(), theta};
  double sum2 = 0, sum_h = 0;
  for (const auto& [p, q] : pairs) {
    const double d = (r * p->head<2>() + t - q->head<2>()).norm();
    const double h = std::fabs(common::wrapToPi(p->z() + theta - q->z()));
    sum2 += d * d;
    sum_h += h;
    out.ate_max_m = std::max(out.ate_max_m, d);
    out.heading_max_abs_rad = std::max(out.heading_max_abs_rad, h);
  }
  out.ate_rmse_m = std::sqrt(sum2 / static_cast<double>(pairs.size()));
  out.heading_mean_abs_rad = sum_h / static_cast<double>(pairs.size());
  return out;
}

std::vector<PoseGraphVertex> readReferencePoses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path + ": cannot open reference poses");
  std::stringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  if (text.find("VERTEX") != std::string::npos) {
    PoseGraph g = parsePoseGraph(text, path);
    if (g.vertices.empty()) throw common::InputError(path + ": no VERTEX lines");
    return g.vertices;
  }
  std::vector<PoseGraphVertex> out;
  std::istringstream lines(text);
  std::string line;
  long lineno = 0;
  while (std::getline(lines, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::vector<double> v;
    std::string tok;
    bool numbers = true;
    while (ls >> tok) {
      const auto d = common::parseDecimal(tok);
      numbers = numbers && d && std::abs(*d) <= common::kMaxCoordinate;
      v.push_back(d ? *d : 0.0);
    }
    if (v.empty()) continue;
    if (!numbers || (v.size() != 3 && v.size() != 4))
      throw common::InputError(path + ":" + std::to_string(lineno) +
                               ": want 'id x y theta' or 'x y theta' (decimal numbers, |value| <= 1e7)");
    if (v.size() == 4)
      out.push_back({static_cast<long>(v[0]), Vec3(v[1], v[2], v[3])});
    else
      out.push_back({static_cast<long>(out.size()), Vec3(v[0], v[1], v[2])});
  }
  if (out.empty()) throw common::InputError(path + ": no poses");
  return out;
}

}  // namespace urbanslam::esdf
