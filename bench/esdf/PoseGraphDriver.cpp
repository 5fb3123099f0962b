// esdf_pose_graph: runs the ESDF back end on pose-graph files with tunable recovery settings
// and prints one line per file (chi2, time, recoveries). For tuning and quick comparisons; the
// user-facing tool is `urbanslam graph`.
//   esdf_pose_graph [--every N] [--innov CHI2] [--window W] [--passes P] [--no-relin] [--gap F]
//                   [--heading RAD] [--heading-steps N] [--no-headings-first] FILE...
//   esdf_pose_graph --eval EDGES_FILE POSES_FILE   chi2 of EDGES_FILE's edges at POSES_FILE's vertices
//   esdf_pose_graph --init IN OUT                  IN with dead-reckoned vertices (for batch tools
//                                                  that need VERTEX lines), written as g2o
//   esdf_pose_graph --error REFERENCE ESTIMATE      ATE RMSE (m, after rigid alignment) and mean
//                                                  absolute heading error (deg) of ESTIMATE's
//                                                  vertices against REFERENCE (see TrajectoryError.h)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseGraphBackend.h"
#include "urbanslam/esdf/TrajectoryError.h"

using namespace urbanslam;

namespace {
constexpr const char* kUsage =
    "usage: esdf_pose_graph [--every N] [--innov CHI2] [--window W] [--passes P] [--no-relin] [--gate]\n"
    "                       [--metis | --auto] [--conservative] [--gap F] [--heading RAD] [--heading-steps N]\n"
    "                       [--no-headings-first] FILE...\n"
    "       esdf_pose_graph --eval EDGES_FILE POSES_FILE\n"
    "       esdf_pose_graph --init IN OUT\n"
    "       esdf_pose_graph --error REFERENCE ESTIMATE\n"
    "Runs the ESDF back end on pose-graph files and prints one line per file (chi2, time, recoveries).\n";
}  // namespace

int main(int argc, char** argv) {
  esdf::PoseGraphBackendOptions o;
  int rc = 0;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--help") || !std::strcmp(argv[a], "-h")) {
      std::printf("%s", kUsage);
      return 0;
    }
    auto next = [&]() { return a + 1 < argc ? argv[++a] : (std::fprintf(stderr, "missing value\n"), std::exit(2), ""); };
    if (!std::strcmp(argv[a], "--eval") && a + 2 < argc) {
      const esdf::PoseGraph edges = esdf::readPoseGraph(argv[a + 1]);
      const esdf::PoseGraph poses = esdf::readPoseGraph(argv[a + 2]);
      std::vector<long> ids;
      std::vector<esdf::Vec3> x;
      for (const auto& v : poses.vertices) {
        ids.push_back(v.id);
        x.push_back(v.pose);
      }
      std::printf("%.6f\n", esdf::poseGraphChi2(edges, x, ids));
      return 0;
    }
    if (!std::strcmp(argv[a], "--error") && a + 2 < argc) {
      try {
        const auto e = esdf::trajectoryError(esdf::readPoseGraph(argv[a + 2]).vertices, esdf::readReferencePoses(argv[a + 1]));
        std::printf("%.6f %.6f %zu\n", e.ate_rmse_m, e.heading_mean_abs_rad * 180.0 / M_PI, e.matched);
        return 0;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
      }
    }
    if (!std::strcmp(argv[a], "--init") && a + 2 < argc) {
      // Dead reckoning through the back end's augmenting edges = the filter before any update.
      esdf::PoseGraph g = esdf::readPoseGraph(argv[a + 1]);
      o.dead_reckoning_only = true;
      o.filter.relinearise = false;
      const auto r = esdf::runPoseGraphBackend(g, o);
      esdf::writePoseGraph(esdf::withPoses(g, r), argv[a + 2], esdf::PoseGraphFormat::G2o);
      return 0;
    }
    if (!std::strcmp(argv[a], "--every"))
      o.full_recovery_every_closures = std::atoi(next());
    else if (!std::strcmp(argv[a], "--innov"))
      o.full_recovery_innovation_chi2 = std::atof(next());
    else if (!std::strcmp(argv[a], "--window"))
      o.recent_window_poses = std::atoi(next());
    else if (!std::strcmp(argv[a], "--passes"))
      o.incremental_relinearise_passes = std::atoi(next());
    else if (!std::strcmp(argv[a], "--no-relin"))
      o.filter.relinearise = false;
    else if (!std::strcmp(argv[a], "--gate"))
      o.gate_loop_closures = true;
    else if (!std::strcmp(argv[a], "--metis"))
      o.filter.ordering = esdf::FillReducingOrdering::Metis;
    else if (!std::strcmp(argv[a], "--auto"))
      o.filter.ordering = esdf::FillReducingOrdering::Auto;
    else if (!std::strcmp(argv[a], "--conservative"))
      o.filter.gate_covariance = esdf::CovarianceMode::Conservative;
    else if (!std::strcmp(argv[a], "--gap"))
      o.full_recovery_min_gap_fraction = std::atof(next());
    else if (!std::strcmp(argv[a], "--heading"))
      o.full_recovery_heading_innovation_rad = std::atof(next());
    else if (!std::strcmp(argv[a], "--heading-steps"))
      o.heading_recovery_steps = std::atoi(next());
    else if (!std::strcmp(argv[a], "--no-headings-first")) {
      o.reinitialise_from_headings = false;
      o.filter.commit_heading_branch = false;
    } else if (argv[a][0] == '-') {
      std::fprintf(stderr, "esdf_pose_graph: unknown option or missing values: %s\n%s", argv[a], kUsage);
      return 2;
    } else {
      try {
        common::Stopwatch sw;
        const esdf::PoseGraph g = esdf::readPoseGraph(argv[a]);
        const double read_s = sw.seconds();
        const auto r = esdf::runPoseGraphBackend(g, o);
        std::printf(
            "%-60s rejected %d poses %6zu edges %6d chi2 %14.6f time %7.3f s (read %.3f, recovery %.3f) full %5d partial %5d "
            "relin %8lld final passes %d%s p50 %.4f p99 %.4f ms\n",
            argv[a], r.rejected_edges, r.poses.size(), r.edges, r.chi2, r.time_s, read_s, r.recovery_s, r.full_recoveries,
            r.partial_recoveries, r.factors_relinearised, r.final_relinearise_passes, r.converged ? " (converged)" : " (NOT converged)",
            common::percentile(r.step_ms, 50), common::percentile(r.step_ms, 99));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", argv[a], e.what());
        rc = 2;  // a file that cannot be read as a pose graph; the others still run
      }
    }
  }
  return rc;
}
