// esdf_pose_graph: runs the ESDF back end on pose-graph files with tunable recovery settings
// and prints one line per file (chi2, time, recoveries). For tuning and quick comparisons; the
// user-facing tool is `urbanslam graph`.
//   esdf_pose_graph [--every N] [--innov CHI2] [--window W] [--passes P] [--no-relin] FILE...
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseGraphBackend.h"

using namespace urbanslam;

int main(int argc, char** argv) {
  esdf::PoseGraphBackendOptions o;
  int rc = 0;
  for (int a = 1; a < argc; ++a) {
    auto next = [&]() { return a + 1 < argc ? argv[++a] : (std::fprintf(stderr, "missing value\n"), std::exit(2), ""); };
    if (!std::strcmp(argv[a], "--every")) o.full_recovery_every_closures = std::atoi(next());
    else if (!std::strcmp(argv[a], "--innov")) o.full_recovery_innovation_chi2 = std::atof(next());
    else if (!std::strcmp(argv[a], "--window")) o.recent_window_poses = std::atoi(next());
    else if (!std::strcmp(argv[a], "--passes")) o.incremental_relinearise_passes = std::atoi(next());
    else if (!std::strcmp(argv[a], "--no-relin")) o.filter.relinearise = false;
    else if (!std::strcmp(argv[a], "--gate")) o.gate_loop_closures = true;
    else {
      try {
        common::Stopwatch sw;
        const esdf::PoseGraph g = esdf::readPoseGraph(argv[a]);
        const double read_s = sw.seconds();
        const auto r = esdf::runPoseGraphBackend(g, o);
        std::printf("%-60s poses %6zu edges %6d chi2 %14.6f time %7.3f s (read %.3f, recovery %.3f) full %5d partial %5d "
                    "relin %8lld p50 %.4f p99 %.4f ms\n",
                    argv[a], r.poses.size(), r.edges, r.chi2, r.time_s, read_s, r.recovery_s, r.full_recoveries,
                    r.partial_recoveries, r.factors_relinearised, common::percentile(r.step_ms, 50),
                    common::percentile(r.step_ms, 99));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", argv[a], e.what());
        rc = 1;
      }
    }
  }
  return rc;
}
