#include "urbanslam/sim/SimulationOutputs.h"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/RawlogWriter.h"
#include "urbanslam/sim/LoopTruth.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/sim/WallsOutput.h"

namespace urbanslam::sim {

SimulationSummary writeSimulation(const SimOptions& options, const std::string& dir, const std::string& resolved_ini,
                                  const std::function<void(double)>& progress) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw common::InputError(dir + ": cannot create the output folder (" + ec.message() + ")");

  SimulationSummary sum;
  SimulatedSource source(options);
  io::RawlogWriter rawlog(dir + "/city.rawlog", io::RawlogLayout::Observations);
  common::AtomicFile loops(dir + "/loops.csv");
  loops.stream() << "t_old,t_new,overlap,distance_m\n";
  LoopTruthFinder finder(options.loops);
  // The truth at scan times: 32 bytes a scan (a 1000 km drive: ~3 MB), written at the end.
  std::vector<io::StampedPose> truth;
  common::Pose2 last_truth;
  bool have_truth = false;

  double sim_s = 0;
  io::Measurement m;
  char buf[160];
  for (size_t k = 0;; ++k) {
    const auto t0 = Clock::now();
    const bool more = source.next(m);
    sim_s += std::chrono::duration<double>(Clock::now() - t0).count();
    if (!more) break;
    rawlog.write(m);
    ++sum.measurements;
    if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
      truth.push_back({ref->timestamp, ref->pose});
      last_truth = ref->pose;
      have_truth = true;
    } else if (const auto* scan = std::get_if<io::LaserScan>(&m)) {
      ++sum.scans;
      if (have_truth) {  // the source yields the scan's reference pose just before it
        for (const LoopPair& p : finder.add(*scan, last_truth)) {
          std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.4f,%.3f\n", p.t_old, p.t_new, p.overlap, p.distance_m);
          loops.stream() << buf;
          ++sum.loop_pairs;
        }
      }
    } else if (std::holds_alternative<io::OdometryReading>(m)) {
      ++sum.odometry;
    } else if (std::holds_alternative<io::GpsFix>(m)) {
      ++sum.gps;
    }
    if (progress && k % 256 == 0) progress(source.progress());
  }
  rawlog.close();
  loops.commit();
  io::writeTum(dir + "/truth.tum", truth);
  const WallsSummary walls = writeWalls(source.city(), source.seenTiles(), dir + "/walls.csv", dir + "/walls.png");
  common::AtomicFile config(dir + "/config.ini");
  config.stream() << resolved_ini;
  config.commit();

  sum.duration_s = source.vehicle().time_s;
  sum.distance_m = source.vehicle().odometer_m;
  sum.wall_segments = walls.segments;
  sum.tiles_seen = source.seenTiles().size();
  sum.tiles_built = source.city().tilesBuilt();
  sum.revisits_planned = source.driver().planner().revisitsPlanned();
  sum.simulate_wall_s = sim_s;
  sum.total_wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return sum;
}

}  // namespace urbanslam::sim
