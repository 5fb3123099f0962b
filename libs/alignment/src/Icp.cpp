#include "urbanslam/alignment/Icp.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/NearestNeighbours.h"
#include "urbanslam/common/RigidFit.h"

namespace urbanslam::alignment {

using common::Pose2;

namespace {

double kernelWeight(RobustKernel kernel, double e, double k) {
  switch (kernel) {
    case RobustKernel::None:
      return 1.0;
    case RobustKernel::Huber:
      return e <= k ? 1.0 : k / e;
    case RobustKernel::Cauchy:
      return 1.0 / (1.0 + (e / k) * (e / k));
  }
  return 1.0;
}

bool finitePose(const Pose2& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.phi); }

}  // namespace

RegistrationResult icpWithIndex(const PointSet& reference, const NearestNeighbours& index, const std::vector<LineNormal>& normals,
                                const PointSet& moving, const Pose2& guess, const IcpOptions& options) {
  RegistrationResult result;
  result.transform = guess;
  const int min_matches = std::max(3, options.min_matches);
  if (static_cast<int>(reference.size()) < min_matches || static_cast<int>(moving.size()) < min_matches) {
    std::ostringstream os;
    os << "too few points (reference " << reference.size() << ", moving " << moving.size() << "; need " << min_matches << ")";
    result.failure_reason = os.str();
    return result;
  }
  if (!normals.empty() && normals.size() != reference.size()) {
    result.failure_reason = "line normals do not belong to the reference scan";
    return result;
  }
  if (!finitePose(guess)) {
    result.failure_reason = "initial guess is not finite";
    return result;
  }
  const bool point_to_line = !normals.empty();
  const double seen_side_tolerance = options.seen_side_tolerance_deg * M_PI / 180;
  const double gate_final = std::max(1e-6, options.gate_final_m);
  double gate = std::max(gate_final, options.gate_initial_m);
  Pose2 pose = guess, before_last = guess;
  bool settled = false;

  std::vector<Eigen::Vector2d> src, dst;
  std::vector<double> w;
  std::vector<int> ref_index, mov_index;
  // Each point's last association: near convergence the pose moves by little and most points
  // keep their nearest reference point (NearestNeighbours::Memo).
  std::vector<NearestNeighbours::Memo> memos(moving.size());
  src.reserve(moving.size());
  dst.reserve(moving.size());
  w.reserve(moving.size());
  ref_index.reserve(moving.size());

  // One association pass at `pose` and `gate`; fills src/dst/w/ref_index.
  auto associate = [&](const Pose2& at, double g) {
    src.clear();
    dst.clear();
    w.clear();
    ref_index.clear();
    mov_index.clear();
    const Rigid2 T = Rigid2::fromPose(at);
    // The kernel acts once the gate has shrunk to its final size: in the coarse iterations it
    // only slowed the pull towards the right basin (bench), near the answer it keeps occluded
    // and cluttered pairs from biasing the estimate.
    const bool robust = g <= gate_final * (1 + 1e-9);
    const double k = options.kernel_scale_m;
    for (size_t i = 0; i < moving.size(); ++i) {
      const ScanPoint& q = moving[i];
      const Eigen::Vector2d m = T * q.p;
      int j = 0;
      double d2 = 0;
      if (!index.nearestWithin(m, g * g, &memos[i], &j, &d2)) continue;
      if (point_to_line && !seenFromSameSide(normals[j], reference[j], T * q.origin, seen_side_tolerance)) continue;
      double e = std::sqrt(d2);
      if (point_to_line && normals[j].valid) e = std::abs(normals[j].n.dot(m - reference[j].p));
      src.push_back(q.p);
      dst.push_back(reference[j].p);
      w.push_back(robust ? kernelWeight(options.kernel, e, k) : 1.0);
      ref_index.push_back(j);
      mov_index.push_back(static_cast<int>(i));
    }
  };

  int it = 0;
  for (it = 1; it <= options.max_iterations; ++it) {
    associate(pose, gate);
    if (static_cast<int>(src.size()) < min_matches) {
      std::ostringstream os;
      os << "only " << src.size() << " associations within the " << gate << " m gate (need " << min_matches << ")";
      result.failure_reason = os.str();
      result.iterations = it;
      result.transform = pose;
      return result;
    }
    Pose2 next = pose;
    if (!point_to_line) {
      if (!common::fitRigid2D(src, dst, w, &next)) break;
    } else {
      // Gauss-Newton on (x, y, phi): line pairs give a scalar residual along the normal, pairs
      // without a line the 2D point residual.
      const double c = std::cos(pose.phi), s = std::sin(pose.phi);
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < src.size(); ++i) {
        const Eigen::Vector2d b = src[i];
        const Eigen::Vector2d m(c * b.x() - s * b.y() + pose.x, s * b.x() + c * b.y() + pose.y);
        const Eigen::Vector2d dm(-s * b.x() - c * b.y(), c * b.x() - s * b.y());  // d m / d phi
        const Eigen::Vector2d r = m - dst[i];
        const LineNormal& ln = normals[ref_index[i]];
        if (ln.valid) {
          const Eigen::Vector3d J(ln.n.x(), ln.n.y(), ln.n.dot(dm));
          const double e = ln.n.dot(r);
          H += w[i] * J * J.transpose();
          g += w[i] * J * e;
        } else {
          Eigen::Matrix<double, 2, 3> J;
          J << 1, 0, dm.x(), 0, 1, dm.y();
          H += w[i] * J.transpose() * J;
          g += w[i] * J.transpose() * r;
        }
      }
      // A little damping keeps the step defined when the geometry leaves a direction free
      // (corridor): that direction then stays at the guess instead of running off.
      H.diagonal().array() += 1e-9 + 1e-6 * H.trace();
      const Eigen::Vector3d d = -H.ldlt().solve(g);
      if (!d.allFinite()) break;
      next = {pose.x + d.x(), pose.y + d.y(), common::wrapToPi(pose.phi + d.z())};
    }
    const double dt = std::hypot(next.x - pose.x, next.y - pose.y);
    const double dphi = std::abs(common::wrapToPi(next.phi - pose.phi));
    // Two sets of pairs that each lead to the other's pose (a pair that counts at one pose and
    // not at the other: the nearest neighbour changes, or a sensor crosses a line's side) make
    // the estimate alternate between the two for ever: at this gate, that is as settled as it gets.
    const bool alternating = it > 2 && std::hypot(next.x - before_last.x, next.y - before_last.y) < options.tolerance_m &&
                             std::abs(common::wrapToPi(next.phi - before_last.phi)) < options.tolerance_rad;
    before_last = pose;
    pose = next;
    if (gate <= gate_final * (1 + 1e-9)) {
      if ((dt < options.tolerance_m && dphi < options.tolerance_rad) || alternating) {
        settled = true;
        break;
      }
    } else if ((dt < 0.05 * gate && dphi < 0.01 * gate) || alternating) {
      if (gate <= options.abandon_gate_factor * gate_final &&
          static_cast<double>(src.size()) < options.abandon_below_fraction * static_cast<double>(moving.size())) {
        std::ostringstream os;
        os << "only " << src.size() << " of " << moving.size() << " points within the " << gate << " m gate (the caller needs "
           << static_cast<int>(100 * options.abandon_below_fraction) << " % within " << gate_final << " m)";
        result.failure_reason = os.str();
        result.iterations = it;
        result.transform = pose;
        return result;
      }
      // Settled relative to the current gate: tighten it (thesis: "a progressively smaller gate").
      gate = std::max(gate_final, gate * options.gate_shrink);
    }
  }
  result.iterations = std::min(it, options.max_iterations);
  result.transform = pose;

  associate(pose, gate_final);
  const Rigid2 T = Rigid2::fromPose(pose);
  double sse = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    result.matches.push_back({mov_index[i], ref_index[i], w[i]});
    const Eigen::Vector2d r = T * src[i] - dst[i];
    const LineNormal* ln = point_to_line ? &normals[ref_index[i]] : nullptr;
    sse += (ln && ln->valid) ? std::pow(ln->n.dot(r), 2) : r.squaredNorm();
  }
  result.rms_residual_m = src.empty() ? 0.0 : std::sqrt(sse / static_cast<double>(src.size()));

  const double overlap = static_cast<double>(src.size()) / static_cast<double>(moving.size());
  if (!settled) {
    std::ostringstream os;
    os << "did not settle within " << options.max_iterations << " iterations";
    result.failure_reason = os.str();
  } else if (static_cast<int>(src.size()) < min_matches || overlap < options.min_overlap) {
    std::ostringstream os;
    os << "only " << src.size() << " of " << moving.size() << " points (" << static_cast<int>(100 * overlap) << " %) match within "
       << gate_final << " m";
    result.failure_reason = os.str();
  } else {
    result.converged = true;
  }
  return result;
}

RegistrationResult icp(const PointSet& reference, const PointSet& moving, const Pose2& guess, const IcpOptions& options) {
  const IndexedReference ref(reference);
  return icpWithIndex(ref.points(), ref.index(), {}, moving, guess, options);
}

RegistrationResult plIcp(const PointSet& reference, const PointSet& moving, const Pose2& guess, const IcpOptions& options) {
  const IndexedReference ref(reference);
  return icpWithIndex(ref.points(), ref.index(), ref.normals(options.normals), moving, guess, options);
}

}  // namespace urbanslam::alignment
