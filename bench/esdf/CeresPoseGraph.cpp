// ceres_pose_graph: the weighted batch optimum of a 2D pose graph with Ceres, as the peer of
// `urbanslam graph` in bench/esdf/run_pose_graphs.sh. MRPT 2.5's graph-slam drops the edges'
// information matrices, so it cannot tell whether the filter reaches the *weighted* optimum.
//
//   ceres_pose_graph IN [--init auto|vertices|odometry] [--max-iterations N] [--out OUT.g2o]
//
// The graph is read with the same PoseGraphIO as urbanslam, each edge's residual is
// L' e with e = ⊖z ⊕ (⊖a ⊕ b) (heading difference wrapped, as the filter and the g2o chi2 do)
// and Omega = L L', pose 0 is held fixed (the gauge; urbanslam anchors it with a tight prior),
// and the problem is solved by Levenberg-Marquardt with sparse Cholesky (SuiteSparse), one
// thread (urbanslam is single-threaded). The initial guess: the file's vertices when every
// vertex has one (`auto`, `vertices`), else (or with `odometry`) dead reckoning through the
// same spanning edges urbanslam's back end augments with, which is what the filter starts from.
// Prints one JSON object: chi2 (evaluated by PoseGraphIO's poseGraphChi2, the same code as for
// urbanslam), initial_chi2, time_s (solve), total_s (read + initial guess + solve), iterations.
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Cholesky>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseGraphBackend.h"
#include "urbanslam/esdf/PoseGraphIO.h"

using namespace urbanslam;

namespace {

// Wraps an angle to [-pi, pi); works on ceres::Jet (floor is overloaded, derivative 1).
template <typename T>
T wrapAngle(const T& a) {
  const T two_pi(2.0 * M_PI);
  return a - two_pi * ceres::floor((a + T(M_PI)) / two_pi);
}

// Residual L' e of one edge, e = ⊖z ⊕ (⊖a ⊕ b).
struct EdgeResidual {
  EdgeResidual(const esdf::Vec3& z, const esdf::Mat3& sqrt_info_t) : z_(z), l_t_(sqrt_info_t) {}

  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    // h = ⊖a ⊕ b: the pose of b in a's frame.
    const T ca = ceres::cos(a[2]), sa = ceres::sin(a[2]);
    const T dx = b[0] - a[0], dy = b[1] - a[1];
    const T hx = ca * dx + sa * dy, hy = -sa * dx + ca * dy, ht = b[2] - a[2];
    // e = ⊖z ⊕ h: h expressed in z's frame, relative to z.
    const double cz = std::cos(z_.z()), sz = std::sin(z_.z());
    const T ex = cz * (hx - z_.x()) + sz * (hy - z_.y());
    const T ey = -sz * (hx - z_.x()) + cz * (hy - z_.y());
    const T et = wrapAngle(ht - T(z_.z()));
    for (int i = 0; i < 3; ++i) r[i] = l_t_(i, 0) * ex + l_t_(i, 1) * ey + l_t_(i, 2) * et;
    return true;
  }

  esdf::Vec3 z_;
  esdf::Mat3 l_t_;
};

int usage(int rc) {
  std::fprintf(rc ? stderr : stdout,
               "usage: ceres_pose_graph IN [--init auto|vertices|odometry] [--max-iterations N] [--out OUT.g2o]\n"
               "Batch weighted optimum of a 2D pose graph (Ceres LM, sparse Cholesky); prints one JSON object.\n");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out, init = "auto";
  int max_iterations = 200;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--help" || arg == "-h") return usage(0);
    if ((arg == "--init" || arg == "--max-iterations" || arg == "--out") && a + 1 >= argc) return usage(2);
    if (arg == "--init")
      init = argv[++a];
    else if (arg == "--max-iterations")
      max_iterations = std::atoi(argv[++a]);
    else if (arg == "--out")
      out = argv[++a];
    else if (!arg.empty() && arg[0] == '-')
      return usage(2);
    else if (in.empty())
      in = arg;
    else
      return usage(2);
  }
  if (in.empty() || (init != "auto" && init != "vertices" && init != "odometry") || max_iterations < 1) return usage(2);
  try {
    common::Stopwatch total;
    const esdf::PoseGraph g = esdf::readPoseGraph(in);
    // Dead reckoning through the back end's augmenting edges: ids, sorted, and the filter's
    // starting estimate (the same code path as esdf_pose_graph --init).
    esdf::PoseGraphBackendOptions dr;
    dr.dead_reckoning_only = true;
    dr.filter.relinearise = false;
    const esdf::PoseGraphBackendResult start = esdf::runPoseGraphBackend(g, dr);
    const std::vector<long>& ids = start.vertex_ids;
    std::unordered_map<long, size_t> index;
    for (size_t k = 0; k < ids.size(); ++k) index.emplace(ids[k], k);
    std::vector<esdf::Vec3> x = start.poses;
    bool from_vertices = false;
    if (init != "odometry") {
      std::vector<char> seen(ids.size(), 0);
      for (const auto& v : g.vertices) seen[index.at(v.id)] = 1;
      const bool all = std::all_of(seen.begin(), seen.end(), [](char c) { return c != 0; });
      if (init == "vertices" && !all) throw common::InputError(in + ": --init vertices: not every vertex has a VERTEX line");
      if (all) {
        for (const auto& v : g.vertices) x[index.at(v.id)] = v.pose;
        from_vertices = true;
      }
    }
    const double initial_chi2 = esdf::poseGraphChi2(g, x, ids);

    common::Stopwatch solve;
    ceres::Problem::Options po;
    ceres::Problem problem(po);
    for (const auto& e : g.edges) {
      // Omega = L L' (Cholesky), so |L' e|^2 = e' Omega e.
      const esdf::Mat3 l = Eigen::LLT<esdf::Mat3>(e.information).matrixL();
      auto* cost = new ceres::AutoDiffCostFunction<EdgeResidual, 3, 3, 3>(new EdgeResidual(e.measurement, l.transpose()));
      problem.AddResidualBlock(cost, nullptr, x[index.at(e.from)].data(), x[index.at(e.to)].data());
    }
    problem.SetParameterBlockConstant(x[0].data());
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    so.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
    so.num_threads = 1;
    so.max_num_iterations = max_iterations;
    so.minimizer_progress_to_stdout = false;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    const double time_s = solve.seconds();
    for (auto& p : x) p.z() = common::wrapToPi(p.z());
    const double chi2 = esdf::poseGraphChi2(g, x, ids);
    if (!out.empty()) {
      esdf::PoseGraphBackendResult r = start;
      r.poses = x;
      esdf::writePoseGraph(esdf::withPoses(g, r), out, esdf::PoseGraphFormat::G2o);
    }
    std::printf(
        "{\"input\":\"%s\",\"poses\":%zu,\"edges\":%zu,\"init\":\"%s\",\"initial_chi2\":%.10g,\"chi2\":%.10g,"
        "\"time_s\":%.6f,\"total_s\":%.6f,\"iterations\":%d,\"termination\":\"%s\",\"usable\":%s}\n",
        in.c_str(), ids.size(), g.edges.size(), from_vertices ? "vertices" : "odometry", initial_chi2, chi2, time_s, total.seconds(),
        static_cast<int>(summary.iterations.size()) - 1, ceres::TerminationTypeToString(summary.termination_type),
        summary.IsSolutionUsable() ? "true" : "false");
  } catch (const common::InputError& e) {
    std::fprintf(stderr, "ceres_pose_graph: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ceres_pose_graph: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
