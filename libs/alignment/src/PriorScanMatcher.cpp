#include "urbanslam/alignment/PriorScanMatcher.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <tuple>
#include <cmath>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/CorrelativeSearch.h"
#include "urbanslam/alignment/MotionPrior.h"
#include "urbanslam/alignment/Voxels.h"

namespace urbanslam::alignment {

namespace {

// The first point of each voxel (sweep order) represents it in the search.
std::vector<Eigen::Vector2d> thin(const PointSet& scan, double voxel_m) {
  std::vector<Eigen::Vector2d> out;
  for (const size_t i : firstPerVoxel(scan, voxel_m)) out.push_back(scan[i].p);
  return out;
}

}  // namespace

MatchReference::MatchReference(PointSet points, const Eigen::Vector2d& centre, const PriorMatcherOptions& options,
                               std::vector<ReferenceView> views)
    : indexed_(std::move(points)),
      grid_(indexed_.points(), centre, options.grid),
      views_(std::move(views)),
      thinned_(thin(indexed_.points(), options.voxel_m)) {}

PriorMatchResult matchWithPrior(const MatchReference& reference, const PointSet& scan, const common::Pose2& prior_mean,
                                const Eigen::Matrix3d& prior_cov, const PriorMatcherOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  PriorMatchResult out;
  out.pose = prior_mean;
  out.cov = prior_cov;
  const std::vector<Eigen::Vector2d> thinned = thin(scan, o.voxel_m);
  out.voxels = static_cast<int>(thinned.size());
  out.points = static_cast<int>(scan.size());
  const auto finish = [&] {
    out.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
  if (out.voxels < o.min_points || reference.indexed().points().empty()) {
    out.failure_reason = "too few points";
    return finish();
  }
  // 1. The window: the configured reach, wider where the prior's 3σ is.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> exy(prior_cov.topLeftCorner<2, 2>());
  const double sxy = std::sqrt(std::max(0.0, exy.eigenvalues().maxCoeff())), sphi = std::sqrt(std::max(0.0, prior_cov(2, 2)));
  CorrelativeWindow window;
  // The uniform share stands for odometry that is wrong in direction, not only in size (reversing
  // reported as driving forwards): the vehicle is anywhere within the travelled distance of where
  // it started, up to twice that from the odometry's pose (or as far as the caller knows it to be,
  // o.direction_reach_m).
  const double reach = o.direction_reach_m >= 0 ? o.direction_reach_m : 2 * std::hypot(prior_mean.x, prior_mean.y);
  const double full_half_width_m = std::min(o.max_search_window_m, std::max({o.search_window_m, 3 * sxy, reach}));
  window.half_width_m =
      o.search_direction_reach ? full_half_width_m : std::min(o.max_search_window_m, std::max(o.search_window_m, 3 * sxy));
  const auto half_angle_rad = [&](double scale) {
    return std::min(o.max_search_window_deg, std::max(o.search_window_deg, scale * 3 * sphi * 180 / M_PI)) * M_PI / 180;
  };
  const double full_half_angle_rad = half_angle_rad(1.0);
  window.half_angle_rad = half_angle_rad(std::min(1.0, o.heading_window_scale));
  const double volume = 4 * full_half_width_m * full_half_width_m * 2 * full_half_angle_rad;
  const MotionPrior prior(prior_mean, prior_cov, o.odometry_outlier_probability, volume);
  out.search_half_angle_rad = window.half_angle_rad;
  out.search_half_width_m = window.half_width_m;
  out.window_narrowed = window.half_width_m < full_half_width_m || window.half_angle_rad < full_half_angle_rad;
  CorrelativeResult coarse = correlativeSearch(reference.grid(), thinned, prior, window);
  out.search_nodes = coarse.nodes;
  // Free space of both sides at a pose: points in view and seen through (reference points in the
  // scan's beams, the scan's points in the reference scans' beams).
  const BeamFreeSpace scan_beams(scan, o.free_margin_m, o.free_margin_fraction);
  const auto freeSpace = [&](const common::Pose2& pose, std::pair<double, int>* in_view_score = nullptr) {
    std::vector<char> ref_state(reference.thinned().size(), BeamFreeSpace::kUnseen);
    scan_beams.classify(reference.thinned(), pose, ref_state);
    std::vector<Eigen::Vector2d> placed;
    const Rigid2 to_ref = Rigid2::fromPose(pose);
    for (const auto& p : thinned) placed.push_back(to_ref * p);
    std::vector<char> scan_state(placed.size(), BeamFreeSpace::kUnseen);
    for (const ReferenceView& v : reference.views()) v.beams.classify(placed, v.pose, scan_state);
    std::pair<int, int> n{0, 0};  // in view, seen through
    for (const auto* states : {&ref_state, &scan_state})
      for (char c : *states) {
        n.first += c != BeamFreeSpace::kUnseen;
        n.second += c == BeamFreeSpace::kSeenThrough;
      }
    if (in_view_score) {
      // The scan's points where the reference has looked (not hidden behind what it saw): their
      // mean log-likelihood.
      double sum = 0;
      int k = 0;
      const LikelihoodGrid& grid = reference.grid();
      for (size_t i = 0; i < placed.size(); ++i) {
        if (scan_state[i] < BeamFreeSpace::kInView) continue;
        sum += grid.score(placed[i]);
        ++k;
      }
      *in_view_score = {sum, k};
    }
    return n;
  };
  // 2'. The scan outvotes the odometry: the best pose the odometry allows, and both weighed again
  // with the free space of both sides (each point in view, independently, seen through or not at
  // the rates of a right and of a displaced pose).
  if (o.seen_through_rate > 0 && scan_beams.valid() && prior.gaussianWeight(prior.mahalanobis2(prior.difference(coarse.pose))) < 0.5) {
    // "The odometry is right": its Gaussian alone, over the same window.
    const MotionPrior odometry_right(prior_mean, prior_cov, 0.0, volume);
    const CorrelativeResult near = correlativeSearch(reference.grid(), thinned, odometry_right, window);
    out.search_nodes += near.nodes;
    // Per point in view: log p(what it shows | right pose) / p(... | wrong pose).
    const double right = std::clamp(o.seen_through_rate, 1e-6, 0.5);
    const double wrong = std::clamp(o.seen_through_rate_displaced, right, 1 - 1e-6);
    const auto full = [&](const CorrelativeResult& c) {
      std::pair<double, int> scored{0, 0};
      const auto [in_view, seen] = freeSpace(c.pose, &scored);
      // A scan point where the reference never looked says nothing about the pose: it counts
      // as the hypothesis's own points in view do on average, so a pose that turns the scan
      // towards new ground is not scored down for it (nor one that folds it onto old ground up).
      const double scan = scored.second >= o.min_points ? thinned.size() * scored.first / scored.second : c.scan_score;
      return scan + prior.logDensity(c.pose) + seen * std::log(right / wrong) + (in_view - seen) * std::log((1 - right) / (1 - wrong));
    };
    // And the odometry's own pose: the searches maximise the plain score, which still marks the
    // scan down for what it sees of new ground.
    CorrelativeResult at_prior;
    at_prior.pose = prior_mean;
    const Rigid2 to_ref = Rigid2::fromPose(prior_mean);
    for (const auto& p : thinned) at_prior.scan_score += reference.grid().score(to_ref * p);
    // Each weighing classifies both sides' free space: once per candidate.
    const double full_prior = full(at_prior), full_near = full(near);
    const CorrelativeResult& best_near = full_prior > full_near ? at_prior : near;
    if (std::max(full_prior, full_near) >= full(coarse)) coarse = best_near;
  }
  out.search_pose = coarse.pose;
  out.scan_log_likelihood = coarse.scan_score;

  // 2. Gauss-Newton on the point-to-line residuals and the prior.
  const PointSet& ref = reference.indexed().points();
  const std::vector<LineNormal>& normals = reference.indexed().normals(o.normals);
  const double info = 1.0 / (o.point_sigma_m * o.point_sigma_m), c2 = o.kernel_scale_m * o.kernel_scale_m;
  const double gate2 = o.gate_m * o.gate_m;
  common::Pose2 x = coarse.pose;
  Eigen::Matrix3d H;
  double sum_d2 = 0;
  // Each point's last association: the iterations move the pose by less and less, and most
  // points keep their nearest reference point (NearestNeighbours::Memo).
  std::vector<NearestNeighbours::Memo> memos(scan.size());
  const auto linearise = [&](const common::Pose2& at, Eigen::Vector3d& g, int& matched) {
    H.setZero();
    g.setZero();
    matched = 0;
    sum_d2 = 0;
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(at.phi).toRotationMatrix();
    const Eigen::Vector2d t(at.x, at.y);
    for (size_t i = 0; i < scan.size(); ++i) {
      const Eigen::Vector2d rp = R * scan[i].p, q = rp + t;
      int j = -1;
      double d2 = 0;
      if (!reference.indexed().index().nearestWithin(q, gate2, &memos[i], &j, &d2)) continue;
      ++matched;
      sum_d2 += d2;
      const Eigen::Vector2d dq(-rp.y(), rp.x());  // d q / d phi
      const Eigen::Vector2d e2 = q - ref[static_cast<size_t>(j)].p;
      const LineNormal& n = normals[static_cast<size_t>(j)];
      if (n.valid) {
        const double e = n.n.dot(e2);
        const Eigen::Vector3d J(n.n.x(), n.n.y(), n.n.dot(dq));
        const double w = info / (1.0 + e * e / c2);
        H += w * J * J.transpose();
        g += w * J * e;
      } else {
        Eigen::Matrix<double, 2, 3> J;
        J << 1, 0, dq.x(), 0, 1, dq.y();
        const double w = info / (1.0 + e2.squaredNorm() / c2);
        H += w * J.transpose() * J;
        g += w * J.transpose() * e2;
      }
    }
    const Eigen::Vector3d d = prior.difference(at);
    out.prior_weight = prior.gaussianWeight(prior.mahalanobis2(d));
    H += out.prior_weight * prior.information();
    g += out.prior_weight * prior.information() * d;
  };
  Eigen::Vector3d g;
  int matched = 0;
  for (out.iterations = 0; out.iterations < o.max_iterations; ++out.iterations) {
    linearise(x, g, matched);
    const Eigen::Vector3d step = -H.ldlt().solve(g);
    if (!step.allFinite()) break;
    x = {x.x + step(0), x.y + step(1), common::wrapToPi(x.phi + step(2))};
    if (std::hypot(step(0), step(1)) < 1e-5 && std::abs(step(2)) < 1e-6) break;
  }
  // 3. The posterior covariance at the estimate.
  linearise(x, g, matched);
  const Eigen::Matrix3d cov = H.ldlt().solve(Eigen::Matrix3d::Identity());
  if (!cov.allFinite()) {
    out.failure_reason = "singular refinement";
    return finish();
  }
  out.valid = true;
  out.pose = x;
  out.cov = 0.5 * (cov + cov.transpose());
  // 4. The disagreement of the search and the refinement (header, step 4).
  const Eigen::Vector3d d(coarse.pose.x - x.x, coarse.pose.y - x.y, common::wrapToPi(coarse.pose.phi - x.phi));
  out.spread = d * d.transpose();
  out.matched = matched;
  out.rms_residual_m = matched > 0 ? std::sqrt(sum_d2 / matched) : 0.0;
  out.odometry_outvoted = out.prior_weight < 0.5;
  if (scan_beams.valid() && o.count_free_space) {
    std::tie(out.in_view, out.seen_through) = freeSpace(x);
    const double d = o.displacement_m, a = o.displacement_deg * M_PI / 180;
    for (const common::Pose2& delta :
         {common::Pose2{d, 0, a}, common::Pose2{-d, 0, -a}, common::Pose2{0, d, -a}, common::Pose2{0, -d, a}}) {
      const auto [in_view, seen] = freeSpace(common::compose(x, delta));
      out.displaced_in_view += in_view;
      out.displaced_seen_through += seen;
    }
  }
  return finish();
}

}  // namespace urbanslam::alignment
