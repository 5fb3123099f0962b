#include "urbanslam/alignment/ViewOverlap.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace urbanslam::alignment {

ViewSector viewSector(const PointSet& points, const common::Pose2& sensor_pose) {
  ViewSector v;
  v.sensor_pose = sensor_pose;
  if (points.empty()) return v;
  // A sweep's bearings are angle_min + i * increment: their smallest and largest bound one
  // contiguous interval, whatever range of angles the sensor reports them in.
  double lo = points.front().bearing_rad, hi = lo, far = 0;
  for (const ScanPoint& q : points) {
    lo = std::min(lo, q.bearing_rad);
    hi = std::max(hi, q.bearing_rad);
    far = std::max(far, q.range_m);
  }
  v.mid_rad = 0.5 * (lo + hi);
  v.half_aperture_rad = std::min(M_PI, 0.5 * (hi - lo));
  v.max_range_m = far;
  v.empty = false;
  return v;
}

namespace {

// Whether q (in the sensor's frame) lies within `slack` of the sector.
class SectorTest {
 public:
  explicit SectorTest(const ViewSector& v)
      : whole_(v.half_aperture_rad >= M_PI),
        cos_half_(std::cos(v.half_aperture_rad)),
        range_(v.max_range_m),
        mid_(std::cos(v.mid_rad), std::sin(v.mid_rad)),
        u0_(std::cos(v.mid_rad - v.half_aperture_rad), std::sin(v.mid_rad - v.half_aperture_rad)),
        u1_(std::cos(v.mid_rad + v.half_aperture_rad), std::sin(v.mid_rad + v.half_aperture_rad)) {}

  bool within(const Eigen::Vector2d& q, double slack) const {
    const double r = q.norm();
    if (whole_ || q.dot(mid_) >= r * cos_half_) return r <= range_ + slack;
    // Outside the bearings: the nearest point of the sector is on one of its edges.
    return std::min(edgeDistance2(q, u0_), edgeDistance2(q, u1_)) <= slack * slack;
  }

 private:
  double edgeDistance2(const Eigen::Vector2d& q, const Eigen::Vector2d& u) const {
    const double s = std::clamp(q.dot(u), 0.0, range_);
    return (q - s * u).squaredNorm();
  }

  bool whole_;
  double cos_half_, range_;
  Eigen::Vector2d mid_, u0_, u1_;
};

// Where a pose of B in A's frame puts B's points in A's sensor frame.
class InSensorFrame {
 public:
  InSensorFrame(const common::Pose2& b_in_a, const common::Pose2& sensor)
      : c_(std::cos(b_in_a.phi)),
        s_(std::sin(b_in_a.phi)),
        sc_(std::cos(sensor.phi)),
        ss_(std::sin(sensor.phi)),
        bx_(b_in_a.x),
        by_(b_in_a.y),
        sx_(sensor.x),
        sy_(sensor.y) {}
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
    const double x = c_ * p.x() - s_ * p.y() + bx_ - sx_, y = s_ * p.x() + c_ * p.y() + by_ - sy_;
    return {sc_ * x + ss_ * y, -ss_ * x + sc_ * y};
  }

 private:
  double c_, s_, sc_, ss_, bx_, by_, sx_, sy_;
};

// A box of poses: centre and half-widths in x, y and heading.
struct Cell {
  Eigen::Vector3d c;
  Eigen::Vector3d h;
};

// How many points fall within the gate of the sector, widened for each point by the most any pose
// of the cell moves it from where the cell's centre puts it; stops once `needed` is out of reach.
bool cellReaches(const SectorTest& sector, const common::Pose2& sensor, const PointSet& b, const std::vector<double>& norms,
                 const Cell& cell, double gate_m, int needed) {
  const InSensorFrame place({cell.c.x(), cell.c.y(), cell.c.z()}, sensor);
  const double shift = std::hypot(cell.h.x(), cell.h.y());
  const int n = static_cast<int>(b.size()), may_miss = n - needed;
  int misses = 0;
  for (int i = 0; i < n; ++i) {
    // A turn by up to h_phi moves a point at distance |p| by at most |p| h_phi.
    const double slack = gate_m + shift + norms[static_cast<size_t>(i)] * cell.h.z();
    if (!sector.within(place(b[static_cast<size_t>(i)].p), slack) && ++misses > may_miss) return false;
  }
  return true;
}

}  // namespace

double shareInView(const ViewSector& a, const PointSet& b, const common::Pose2& b_in_a, double gate_m) {
  if (b.empty() || a.empty) return 0.0;
  const SectorTest sector(a);
  const InSensorFrame place(b_in_a, a.sensor_pose);
  int in = 0;
  for (const ScanPoint& pt : b)
    if (sector.within(place(pt.p), gate_m)) ++in;
  return static_cast<double>(in) / static_cast<double>(b.size());
}

bool mayMatchShare(const ViewSector& a, const PointSet& b, const PoseRegion& region, double share, const ViewOverlapOptions& options) {
  if (share <= 0) return true;
  if (b.empty() || a.empty) return false;
  const Eigen::LLT<Eigen::Matrix3d> llt(region.cov);
  if (!region.cov.allFinite() || llt.info() != Eigen::Success || !(region.chi2 > 0)) return true;
  const Eigen::Matrix3d info = llt.solve(Eigen::Matrix3d::Identity());
  const double k = std::sqrt(region.chi2);
  const int needed = static_cast<int>(std::ceil(share * static_cast<double>(b.size()) - 1e-9));
  std::vector<double> norms(b.size());
  for (size_t i = 0; i < b.size(); ++i) norms[i] = b[i].p.norm();
  const SectorTest sector(a);
  const Eigen::Vector3d center(region.center.x, region.center.y, region.center.phi);
  const auto mahalanobis = [&](const Eigen::Vector3d& d) { return std::sqrt(std::max(0.0, d.dot(info * d))); };
  // The cell may hold a pose of the region: the region's Mahalanobis distance to its centre,
  // less the largest to a corner (the norm's triangle inequality), is within the gate.
  const auto touches = [&](const Cell& cell) {
    Eigen::Vector3d d = cell.c - center;
    d.z() = common::wrapToPi(d.z());
    double corner = 0;
    for (const double sy : {-1.0, 1.0})
      for (const double sz : {-1.0, 1.0}) corner = std::max(corner, mahalanobis({cell.h.x(), sy * cell.h.y(), sz * cell.h.z()}));
    return mahalanobis(d) - corner <= k;
  };
  // The region's bounding box; a heading spread of pi or more is every heading.
  const Eigen::Vector3d minimum(options.min_cell_translation_m, options.min_cell_translation_m, options.min_cell_heading_rad);
  Cell root{center, Eigen::Vector3d(k * std::sqrt(region.cov(0, 0)), k * std::sqrt(region.cov(1, 1)), k * std::sqrt(region.cov(2, 2)))};
  root.h.z() = std::min(root.h.z(), M_PI);
  // Depth first, the children nearest the region's centre first: a pose that reaches the share
  // is usually near the estimate, and one smallest cell that reaches it settles the question.
  std::vector<Cell> stack{root};
  int examined = 0;
  while (!stack.empty()) {
    if (++examined > options.max_cells) return true;
    const Cell cell = stack.back();
    stack.pop_back();
    if (!cellReaches(sector, a.sensor_pose, b, norms, cell, options.gate_m, needed)) continue;
    std::array<bool, 3> split{};
    int splits = 0;
    for (int d = 0; d < 3; ++d) splits += (split[static_cast<size_t>(d)] = cell.h[d] > minimum[d]) ? 1 : 0;
    if (splits == 0) return true;
    std::vector<std::pair<double, Cell>> children;
    for (int m = 0; m < (1 << 3); ++m) {
      Cell child = cell;
      bool skip = false;
      for (int d = 0; d < 3; ++d) {
        const bool upper = (m >> d) & 1;
        if (!split[static_cast<size_t>(d)]) {
          skip = skip || upper;  // an unsplit dimension: one child along it
          continue;
        }
        child.h[d] = 0.5 * cell.h[d];
        child.c[d] = cell.c[d] + (upper ? child.h[d] : -child.h[d]);
      }
      if (skip || !touches(child)) continue;
      Eigen::Vector3d d = child.c - center;
      d.z() = common::wrapToPi(d.z());
      children.emplace_back(mahalanobis(d), child);
    }
    std::sort(children.begin(), children.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    for (const auto& ch : children) stack.push_back(ch.second);
  }
  return false;
}

}  // namespace urbanslam::alignment
