// esdf_bench: per-step cost of the ESDF versus trajectory length on a synthetic city-grid drive
// with loops (a plain executable: percentiles, not Google Benchmark's means, are the point).
//
// For each size N: a car drives N one-metre steps on a grid of 10 m blocks (random turns at
// intersections, kept inside a square town of about sqrt(N)/3 blocks a side so that it revisits
// streets), with noisy odometry. Revisiting a lattice point seen more than 50 steps earlier gives
// a loop-closure observation (probability 0.3). Reported:
//   * predict+augment per step: p50 / p99 / max (microseconds)
//   * update (observation, information form, no recovery) per closure: p50 / p99 / max
//   * filter storage per pose and process peak RSS
//   * loop-closure update + full recovery (CHOLMOD factorisation + solve) at size N, partial
//     recovery of the 50 most recent poses, and the joint covariance of a pair 20 poses after
//     that factorisation: exact (refactorise + column solves) / conservative (old factor + dead
//     reckoning, no refactorisation).
// Usage: esdf_bench [--no-full-above N] [--ordering amd|metis|auto|natural] [--backend N]...
//                   [--final-passes P] [--min-gap F] [--incremental-passes P] [--heading-recovery RAD]
//                   [--heading-steps N] [--no-headings-first]
//                   SIZE...
//        esdf_bench --write-graph N PREFIX   (the back end's drive as PREFIX.g2o + PREFIX.truth.g2o)
//   (default sizes 1000 10000 100000 1000000; each --backend N also runs the pose-graph back end,
//   with its recovery policy, on the same drive of N poses)
#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseGraphBackend.h"
#include "urbanslam/esdf/PoseGraphIO.h"

using namespace urbanslam;
using esdf::Mat3;
using esdf::Vec3;

namespace {

struct Row {
  long n = 0;
  long closures = 0;
  double aug_p50 = 0, aug_p99 = 0, aug_max = 0;
  double upd_p50 = 0, upd_p99 = 0, upd_max = 0;
  double bytes_per_pose = 0;
  double full_s = -1, partial_ms = 0, cov_exact_ms = -1, cov_cons_ms = -1;
  long long factor_nnz = 0;
};

esdf::FillReducingOrdering g_ordering = esdf::FillReducingOrdering::Amd;

Row runSize(long n, long no_full_above) {
  std::mt19937 rng(static_cast<unsigned>(n));
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  esdf::EsdfOptions opt;
  opt.relinearise = true;
  opt.ordering = g_ordering;
  esdf::Esdf f(opt);
  f.reserve(static_cast<int>(n));
  f.initialise(Vec3::Zero(), Mat3::Identity() * 1e-8);
  const Mat3 odo = Vec3(400.0, 400.0, 10000.0).asDiagonal();
  const Mat3 loop = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  const int half_blocks = std::max(2, static_cast<int>(std::sqrt(static_cast<double>(n)) / 6));
  std::vector<double> aug_us, upd_us;
  aug_us.reserve(static_cast<size_t>(n));
  std::unordered_map<long long, std::pair<int, Vec3>> last_visit;  // lattice point -> (pose, true pose)
  Vec3 truth = Vec3::Zero();
  int dir = 0;  // 0 +x, 1 +y, 2 -x, 3 -y
  for (long k = 1; k < n; ++k) {
    // Turn at intersections; turn back inward at the town border.
    double dphi = 0;
    const long ix = std::lround(truth.x()), iy = std::lround(truth.y());
    if (ix % 10 == 0 && iy % 10 == 0) {
      const double r = u(rng);
      int turn = r < 0.3 ? 1 : (r < 0.6 ? -1 : 0);
      const int lim = 10 * half_blocks;
      auto outward = [&](int d) {
        return (d == 0 && ix >= lim) || (d == 2 && ix <= -lim) || (d == 1 && iy >= lim) || (d == 3 && iy <= -lim);
      };
      for (int tries = 0; tries < 4 && outward((dir + turn + 4) % 4); ++tries) turn = (turn == 1) ? -1 : turn + 1;
      dir = (dir + turn + 4) % 4;
      dphi = turn * M_PI / 2;
    }
    const Vec3 step(std::cos(dphi), std::sin(dphi), dphi);  // turn, then drive one metre
    truth = esdf::compose(truth, step);
    const Vec3 z = step + Vec3(0.05 * g(rng), 0.05 * g(rng), 0.01 * g(rng));
    common::Stopwatch sw;
    f.augmentRelative(static_cast<int>(k - 1), z, odo);
    aug_us.push_back(1e3 * sw.milliseconds());
    // Loop closure on a revisit.
    const long long key = (static_cast<long long>(std::lround(truth.x())) << 32) ^ (std::lround(truth.y()) & 0xffffffff);
    auto it = last_visit.find(key);
    if (it != last_visit.end() && k - it->second.first > 50 && u(rng) < 0.3) {
      const int i = it->second.first;
      const Vec3 zl = esdf::between(it->second.second, truth) + Vec3(0.05 * g(rng), 0.05 * g(rng), 0.01 * g(rng));
      common::Stopwatch su;
      f.observeRelative(i, static_cast<int>(k), zl, loop);
      upd_us.push_back(1e3 * su.milliseconds());
    }
    last_visit[key] = {static_cast<int>(k), truth};
  }
  Row r;
  r.n = n;
  r.closures = static_cast<long>(upd_us.size());
  r.aug_p50 = common::percentile(aug_us, 50);
  r.aug_p99 = common::percentile(aug_us, 99);
  r.aug_max = common::percentile(aug_us, 100);
  r.upd_p50 = common::percentile(upd_us, 50);
  r.upd_p99 = common::percentile(upd_us, 99);
  r.upd_max = common::percentile(upd_us, 100);
  r.bytes_per_pose = static_cast<double>(f.memoryBytes()) / static_cast<double>(n);
  {
    common::Stopwatch sw;
    f.recoverRecent(static_cast<int>(n) - 50);
    r.partial_ms = sw.milliseconds();
  }
  if (n <= no_full_above) {
    // Loop-closure update + full recovery (one factorisation + solve, no relinearisation: the
    // cost of bringing the whole mean up to date after a closure).
    const int i = static_cast<int>(n / 3), j = static_cast<int>(n - 1);
    common::Stopwatch sw;
    f.observeRelative(i, j, esdf::between(f.mean(i), f.mean(j)), loop);
    f.recover(0);
    r.full_s = sw.seconds();
    r.factor_nnz = f.factorNonZeros();
    // Covariance of a pair for gating a new closure, with the factor now stale (20 new poses and
    // a closure among them): conservative reuses the old factor plus dead reckoning; exact
    // updates the old factor by the closure (ExactUpdates.cpp: column solves, no factorisation).
    for (int k = 0; k < 20; ++k) f.augmentRelative(f.currentPose(), Vec3(1, 0, 0), odo);
    const int a = i + 5, b = f.currentPose() - 2;
    f.observeRelative(a, b, esdf::between(f.mean(a), f.mean(b)), loop);
    common::Stopwatch sc2;
    f.jointCovariance(i, f.currentPose(), esdf::CovarianceMode::Conservative);
    r.cov_cons_ms = sc2.milliseconds();
    common::Stopwatch sc;
    f.jointCovariance(i, f.currentPose(), esdf::CovarianceMode::Exact);
    r.cov_exact_ms = sc.milliseconds();
  }
  return r;
}

// The same drive as a pose graph (odometry + loop-closure edges), for the back end's policy.
// With `truth`, also the true poses (vertex k = pose k).
esdf::PoseGraph cityGraph(long n, std::vector<esdf::PoseGraphVertex>* truth_out = nullptr) {
  std::mt19937 rng(static_cast<unsigned>(n) + 7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  esdf::PoseGraph graph;
  const Mat3 odo = Vec3(400.0, 400.0, 10000.0).asDiagonal();
  const Mat3 loop = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  const int half_blocks = std::max(2, static_cast<int>(std::sqrt(static_cast<double>(n)) / 6));
  std::unordered_map<long long, std::pair<int, Vec3>> last_visit;
  Vec3 truth = Vec3::Zero();
  if (truth_out) truth_out->assign(1, {0, truth});
  int dir = 0;
  for (long k = 1; k < n; ++k) {
    double dphi = 0;
    const long ix = std::lround(truth.x()), iy = std::lround(truth.y());
    if (ix % 10 == 0 && iy % 10 == 0) {
      const double r = u(rng);
      int turn = r < 0.3 ? 1 : (r < 0.6 ? -1 : 0);
      const int lim = 10 * half_blocks;
      auto outward = [&](int d) {
        return (d == 0 && ix >= lim) || (d == 2 && ix <= -lim) || (d == 1 && iy >= lim) || (d == 3 && iy <= -lim);
      };
      for (int tries = 0; tries < 4 && outward((dir + turn + 4) % 4); ++tries) turn = (turn == 1) ? -1 : turn + 1;
      dir = (dir + turn + 4) % 4;
      dphi = turn * M_PI / 2;
    }
    const Vec3 step(std::cos(dphi), std::sin(dphi), dphi);
    truth = esdf::compose(truth, step);
    if (truth_out) truth_out->push_back({k, truth});
    graph.edges.push_back({k - 1, k, step + Vec3(0.05 * g(rng), 0.05 * g(rng), 0.01 * g(rng)), odo});
    const long long key = (static_cast<long long>(std::lround(truth.x())) << 32) ^ (std::lround(truth.y()) & 0xffffffff);
    auto it = last_visit.find(key);
    if (it != last_visit.end() && k - it->second.first > 50 && u(rng) < 0.3) {
      const Vec3 zl = esdf::between(it->second.second, truth) + Vec3(0.05 * g(rng), 0.05 * g(rng), 0.01 * g(rng));
      graph.edges.push_back({it->second.first, k, zl, loop});
    }
    last_visit[key] = {static_cast<int>(k), truth};
  }
  return graph;
}

// --write-graph N PREFIX: the back end's drive of N poses as PREFIX.g2o (edges only, what
// the back end sees) and PREFIX.truth.g2o (the true poses as vertices, plus the same edges),
// for running peers (ceres_pose_graph) and the ground-truth error on the same graph.
void writeGraph(long n, const std::string& prefix) {
  std::vector<esdf::PoseGraphVertex> truth;
  esdf::PoseGraph g = cityGraph(n, &truth);
  esdf::writePoseGraph(g, prefix + ".g2o", esdf::PoseGraphFormat::G2o);
  g.vertices = std::move(truth);
  esdf::writePoseGraph(g, prefix + ".truth.g2o", esdf::PoseGraphFormat::G2o);
}

int g_final_passes = -1;
double g_min_gap = -1;
int g_incremental_passes = -1;
double g_heading_recovery = -1;
int g_heading_steps = -1;
bool g_no_headings_first = false;

void runBackend(const std::vector<long>& sizes) {
  std::printf(
      "\nback end (urbanslam graph's policy: partial recovery after closures, amortised full recoveries,\n"
      "relinearisation; the last recovery iterates to convergence):\n");
  std::printf("%9s %8s | %9s %9s %9s | %8s %8s | %9s %9s | %12s %s\n", "poses", "edges", "step_p50", "step_p99", "step_max", "full",
              "partial", "time_s", "recov_s", "chi2", "");
  for (long n : sizes) {
    std::vector<esdf::PoseGraphVertex> truth;
    const esdf::PoseGraph graph = cityGraph(n, &truth);
    esdf::PoseGraphBackendOptions o;
    if (g_final_passes >= 0) o.filter.relinearise_max_passes = g_final_passes;
    if (g_min_gap >= 0) o.full_recovery_min_gap_fraction = g_min_gap;
    if (g_incremental_passes >= 0) o.incremental_relinearise_passes = g_incremental_passes;
    if (g_heading_recovery >= 0) o.full_recovery_heading_innovation_rad = g_heading_recovery;
    if (g_heading_steps >= 0) o.heading_recovery_steps = g_heading_steps;
    if (g_no_headings_first) {
      o.reinitialise_from_headings = false;
      o.filter.commit_heading_branch = false;
    }
    const auto r = esdf::runPoseGraphBackend(graph, o);
    std::printf("%9ld %8d | %9.4f %9.4f %9.1f | %8d %8d | %9.3f %9.3f | %12.3f %s\n", n, r.edges, common::percentile(r.step_ms, 50),
                common::percentile(r.step_ms, 99), common::percentile(r.step_ms, 100), r.full_recoveries, r.partial_recoveries, r.time_s,
                r.recovery_s, r.chi2, r.converged ? "(converged)" : "(not converged)");
    std::printf(
        "          closures with heading innovation > pi/2 when added: %d (max %.3f rad); "
        "full recoveries forced by the heading innovation: %d\n",
        r.large_heading_innovations, r.max_heading_innovation_rad, r.heading_triggered_recoveries);
    {
      // Against the truth (unwrapped, as the drive composes it): closures added on the wrong
      // heading branch.
      int wrong = 0;
      long first_wrong = -1;
      for (const auto& cb : r.closure_branches) {
        const auto& e = graph.edges[static_cast<size_t>(cb.edge)];
        const double d = truth[static_cast<size_t>(e.to)].pose.z() - truth[static_cast<size_t>(e.from)].pose.z();
        if (std::fabs(cb.heading_diff_rad - d) > M_PI) {
          ++wrong;
          if (first_wrong < 0) first_wrong = e.to;
        }
      }
      std::printf("          closures added on the wrong heading branch (against the truth): %d of %zu", wrong, r.closure_branches.size());
      if (wrong > 0) std::printf(", the first at pose %ld", first_wrong);
      std::printf("\n");
    }
    std::fflush(stdout);
  }
}

}  // namespace

namespace {
constexpr const char* kUsage =
    "usage: esdf_bench [--no-full-above N] [--ordering amd|metis|auto|natural] [--backend N]...\n"
    "                  [--final-passes P] [--min-gap F] [--incremental-passes P] [--heading-recovery RAD]\n"
    "                  [--heading-steps N] [--no-headings-first] SIZE...\n"
    "       esdf_bench --write-graph N PREFIX\n"
    "The ESDF's per-step cost against the length of a synthetic city-grid drive (default sizes\n"
    "1000 10000 100000 1000000); --backend N also runs the pose-graph back end on a drive of N poses.\n";

// A drive length: a whole number of at least 100 poses (the runs look 50 poses back), else exit 2.
long poses(const char* text, const char* what) {
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || n < 100) {
    std::fprintf(stderr, "esdf_bench: %s '%s' is not a number of poses of at least 100\n%s", what, text, kUsage);
    std::exit(2);
  }
  return n;
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<long> sizes, backend_sizes;
  long no_full_above = 100000000;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--help") || !std::strcmp(argv[a], "-h")) {
      std::printf("%s", kUsage);
      return 0;
    }
    if (!std::strcmp(argv[a], "--no-full-above") && a + 1 < argc)
      no_full_above = std::atol(argv[++a]);
    else if (!std::strcmp(argv[a], "--write-graph") && a + 2 < argc) {
      writeGraph(poses(argv[a + 1], "--write-graph"), argv[a + 2]);
      return 0;
    } else if (!std::strcmp(argv[a], "--backend") && a + 1 < argc)
      backend_sizes.push_back(poses(argv[++a], "--backend"));
    else if (!std::strcmp(argv[a], "--final-passes") && a + 1 < argc)
      g_final_passes = std::atoi(argv[++a]);
    else if (!std::strcmp(argv[a], "--min-gap") && a + 1 < argc)
      g_min_gap = std::atof(argv[++a]);
    else if (!std::strcmp(argv[a], "--incremental-passes") && a + 1 < argc)
      g_incremental_passes = std::atoi(argv[++a]);
    else if (!std::strcmp(argv[a], "--heading-recovery") && a + 1 < argc)
      g_heading_recovery = std::atof(argv[++a]);
    else if (!std::strcmp(argv[a], "--heading-steps") && a + 1 < argc)
      g_heading_steps = std::atoi(argv[++a]);
    else if (!std::strcmp(argv[a], "--no-headings-first"))
      g_no_headings_first = true;
    else if (!std::strcmp(argv[a], "--ordering") && a + 1 < argc) {
      const std::string o = argv[++a];
      g_ordering = o == "metis"     ? esdf::FillReducingOrdering::Metis
                   : o == "auto"    ? esdf::FillReducingOrdering::Auto
                   : o == "natural" ? esdf::FillReducingOrdering::Natural
                                    : esdf::FillReducingOrdering::Amd;
    } else if (argv[a][0] == '-') {
      std::fprintf(stderr, "esdf_bench: unknown option or missing value: %s\n%s", argv[a], kUsage);
      return 2;
    } else {
      sizes.push_back(poses(argv[a], "size"));
    }
  }
  if (sizes.empty() && backend_sizes.empty()) sizes = {1000, 10000, 100000, 1000000};
  std::printf("%9s %8s | %8s %8s %9s | %8s %8s %9s | %9s | %10s %12s %10s %10s %10s\n", "poses", "closures", "aug_p50", "aug_p99",
              "aug_max", "upd_p50", "upd_p99", "upd_max", "B/pose", "full_rec_s", "factor_nnz", "part_ms", "cov_ex_ms", "cov_cons_ms");
  std::printf("%9s %8s | %28s | %28s |\n", "", "", "predict+augment (us)", "update (us)");
  for (long n : sizes) {
    const Row r = runSize(n, no_full_above);
    std::printf("%9ld %8ld | %8.3f %8.3f %9.1f | %8.3f %8.3f %9.1f | %9.0f | %10.3f %12lld %10.3f %10.3f %10.3f\n", r.n, r.closures,
                r.aug_p50, r.aug_p99, r.aug_max, r.upd_p50, r.upd_p99, r.upd_max, r.bytes_per_pose, r.full_s, r.factor_nnz, r.partial_ms,
                r.cov_exact_ms, r.cov_cons_ms);
    std::fflush(stdout);
  }
  if (!backend_sizes.empty()) runBackend(backend_sizes);
  std::printf("peak RSS %.1f MB\n", static_cast<double>(common::peakResidentBytes()) / 1e6);
  return 0;
}
