#include "urbanslam/alignment/Aligner.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "urbanslam/alignment/NearestNeighbours.h"
#include "urbanslam/common/Timing.h"

namespace urbanslam::alignment {

using common::Pose2;

AlignmentResult align(const io::LaserScan& a, const io::LaserScan& b, const Pose2& guess, const AlignerOptions& options) {
  common::Stopwatch sw;
  const PointSet pa = pointSetFromScan(a, options.scan, options.in_vehicle_frame);
  const PointSet pb = pointSetFromScan(b, options.scan, options.in_vehicle_frame);
  AlignmentResult r = alignPointSets(pa, pb, guess, options);
  r.time_ms = sw.milliseconds();
  return r;
}

namespace {

// Method prior: the guess as a prior with options.prior_sigma_*; the scan decides wherever it is
// clear (PriorScanMatcher.h).
AlignmentResult alignWithPrior(const MatchReference& reference, const PointSet& b, const Pose2& guess, const AlignerOptions& options) {
  AlignmentResult out;
  const double sxy = options.prior_sigma_m, sphi = options.prior_sigma_deg * M_PI / 180.0;
  const PriorMatchResult m =
      matchWithPrior(reference, b, guess, Eigen::Vector3d(sxy * sxy, sxy * sxy, sphi * sphi).asDiagonal(), options.prior);
  out.transform = m.pose;
  out.converged = m.valid;
  out.failure_reason = m.failure_reason;
  const double max_m = options.covariance.max_std_m, max_rad = options.covariance.max_std_rad;
  out.cov = m.valid ? m.cov : Eigen::Matrix3d(Eigen::Vector3d(max_m * max_m, max_m * max_m, max_rad * max_rad).asDiagonal());
  out.iterations = m.iterations;
  out.matches = m.matched;
  out.rms_residual_m = m.rms_residual_m;
  out.points_a = static_cast<int>(reference.indexed().points().size());
  out.points_b = static_cast<int>(b.size());
  return out;
}

}  // namespace

AlignmentResult alignPointSets(const PointSet& a, const PointSet& b, const Pose2& guess, const AlignerOptions& options) {
  common::Stopwatch sw;
  // (The prior method builds its kd-tree with its grid: no IndexedReference first.)
  AlignmentResult r =
      options.method == Method::Prior && std::isfinite(guess.x) && std::isfinite(guess.y) && std::isfinite(guess.phi)
          ? alignWithPrior(MatchReference(a, Eigen::Vector2d(guess.x, guess.y), options.prior,
                                          {{BeamFreeSpace(a, options.prior.free_margin_m, options.prior.free_margin_fraction), {}}}),
                           b, guess, options)
          : alignPointSets(IndexedReference(a), b, guess, options);
  r.time_ms = sw.milliseconds();
  return r;
}

AlignmentResult alignPointSets(const IndexedReference& indexed, const PointSet& b, const Pose2& guess, const AlignerOptions& options) {
  common::Stopwatch sw;
  const PointSet& a = indexed.points();
  AlignmentResult out;
  out.transform = guess;
  out.points_a = static_cast<int>(a.size());
  out.points_b = static_cast<int>(b.size());
  const Eigen::Matrix3d large = Eigen::Vector3d(options.covariance.max_std_m * options.covariance.max_std_m,
                                                options.covariance.max_std_m * options.covariance.max_std_m,
                                                options.covariance.max_std_rad * options.covariance.max_std_rad)
                                    .asDiagonal();
  out.cov = large;
  if (!std::isfinite(guess.x) || !std::isfinite(guess.y) || !std::isfinite(guess.phi)) {
    out.transform = Pose2{};
    out.failure_reason = "initial guess is not finite";
    out.time_ms = sw.milliseconds();
    return out;
  }

  if (options.method == Method::Prior) {
    // The prior method keeps its own kd-tree next to its likelihood grid (MatchReference): callers
    // with a prepared reference match many scans against one MatchReference instead.
    const MatchReference reference(a, Eigen::Vector2d(guess.x, guess.y), options.prior);
    out = alignWithPrior(reference, b, guess, options);
    out.time_ms = sw.milliseconds();
    return out;
  }
  RegistrationResult reg;
  bool point_to_line = false;
  switch (options.method) {
    case Method::Prior:
      break;  // above
    case Method::Icp:
      reg = icpWithIndex(a, indexed.index(), {}, b, guess, options.icp);
      break;
    case Method::PlIcp:
      point_to_line = true;
      reg = icpWithIndex(a, indexed.index(), indexed.normals(options.icp.normals), b, guess, options.icp);
      break;
    case Method::Crf:
      reg = crfMatch(a, b, guess, options.crf);
      break;
    case Method::CrfIcp: {
      // CRF-match proposes, ICP verifies: ICP runs from the CRF transform, from the CRF's other
      // consensus hypotheses and from the caller's guess; the refinement that explains most
      // points wins (near ties go to the one closest to the guess, the filter's prior). In
      // repetitive scenes (corridors) the CRF's best hypothesis is often a sliding or mirrored
      // one, and a good guess (laser odometry) must never be made worse.
      CrfDiagnostics diag;
      const RegistrationResult coarse = crfMatch(a, b, guess, options.crf, &diag);
      std::vector<Pose2> starts;
      auto addStart = [&](const Pose2& p) {
        // Starts this close converge to the same answer: one ICP run is enough.
        for (const auto& q : starts)
          if (std::hypot(p.x - q.x, p.y - q.y) < 0.2 && std::abs(common::wrapToPi(p.phi - q.phi)) < 0.05) return;
        starts.push_back(p);
      };
      if (coarse.converged) addStart(coarse.transform);
      for (const auto& h : diag.hypotheses) addStart(h);
      addStart(guess);
      point_to_line = options.refine_point_to_line;
      const std::vector<LineNormal> none;
      const std::vector<LineNormal>& normals = point_to_line ? indexed.normals(options.icp.normals) : none;
      bool have = false;
      int total_iterations = coarse.iterations;
      double best_count = -1;
      for (const auto& st : starts) {
        RegistrationResult r = icpWithIndex(a, indexed.index(), normals, b, st, options.icp);
        total_iterations += r.iterations;
        if (!r.converged) {
          if (!have) reg = r;
          continue;
        }
        const double count = static_cast<double>(r.matches.size());
        const auto dist = [&](const Pose2& p) {
          return std::hypot(p.x - guess.x, p.y - guess.y) + 2.0 * std::abs(common::wrapToPi(p.phi - guess.phi));
        };
        const bool better = !have || count > best_count * 1.02 || (count >= best_count * 0.98 && dist(r.transform) < dist(reg.transform));
        if (better) {
          reg = r;
          best_count = std::max(best_count, count);
          have = true;
        }
      }
      reg.iterations = total_iterations;
      if (!have && !coarse.converged) reg.failure_reason = "CRF-match: " + coarse.failure_reason + "; ICP: " + reg.failure_reason;
      break;
    }
  }
  out.transform = reg.transform;
  out.iterations = reg.iterations;
  out.converged = reg.converged;
  out.failure_reason = reg.failure_reason;
  out.matches = static_cast<int>(reg.matches.size());
  out.rms_residual_m = reg.rms_residual_m;

  if (reg.converged) {
    common::Stopwatch csw;
    out.cov = alignmentCovariance(indexed, b, reg.transform, options.icp, point_to_line, options.covariance);
    out.constraint_ratio = translationConstraintRatio(indexed, b, reg.transform, options.covariance);
    out.covariance_time_ms = csw.milliseconds();
    if (out.constraint_ratio < options.min_constraint_ratio) {
      std::ostringstream os;
      os << "degenerate geometry: the scans hardly constrain one direction of translation "
            "(constraint ratio "
         << out.constraint_ratio << " < " << options.min_constraint_ratio << ", e.g. a corridor)";
      out.converged = false;
      out.failure_reason = os.str();
    }
  }
  if (!out.cov.allFinite()) {
    out.cov = large;
    if (out.converged) {
      out.converged = false;
      out.failure_reason = "covariance is not finite";
    }
  }
  out.time_ms = sw.milliseconds();
  return out;
}

Method parseMethod(const std::string& name) {
  if (name == "prior") return Method::Prior;
  if (name == "icp") return Method::Icp;
  if (name == "plicp" || name == "pl-icp") return Method::PlIcp;
  if (name == "crf") return Method::Crf;
  if (name == "crf+icp" || name == "crficp") return Method::CrfIcp;
  throw std::invalid_argument("unknown alignment method '" + name + "' (prior, icp, plicp, crf, crf+icp)");
}

std::string methodName(Method method) {
  switch (method) {
    case Method::Prior:
      return "prior";
    case Method::Icp:
      return "icp";
    case Method::PlIcp:
      return "plicp";
    case Method::Crf:
      return "crf";
    case Method::CrfIcp:
      return "crf+icp";
  }
  return "?";
}

}  // namespace urbanslam::alignment
