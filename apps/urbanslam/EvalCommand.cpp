// `urbanslam eval`: accuracy of a run folder against relations (Kümmerle et al.) and/or a
// reference trajectory, and loop closures classified true/false.
#include <filesystem>
#include <iostream>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/evaluation/RunReport.h"
#include "urbanslam/laser_loop/LinePlot.h"

namespace urbanslam::cli {

namespace fs = std::filesystem;

int evalCommand(const Argv& args) {
  ArgParser ap("urbanslam eval RUN_DIR (--relations FILE | --reference FILE | --truth SIM_DIR) [--json]",
               "Evaluates the output folder of `urbanslam run`:\n"
               "  --relations: the relation metric of Kümmerle et al. 2009 as Cartographer computes it\n"
               "    (error = (p1^-1 p2) expected^-1; abs/squared translational and rotational error, mean +/- std)\n"
               "    on the run's nodes (trajectory_scans.tum: every scan it placed) at each relation time, between\n"
               "    nodes bridged along trajectory_odometry.tum (the odometry's shape, ending on both nodes; where\n"
               "    every relation time is a scan time, as on the raw benchmark logs, Cartographer's figure exactly),\n"
               "    every relation inside the run (the others counted as skipped); relations_linear: the nodes\n"
               "    interpolated linearly instead; relations_odometry: the same on trajectory_odometry.tum (a folder\n"
               "    without trajectory_scans.tum: that one only, linearly);\n"
               "    relations.loops: the accepted closures checked against the relations (a relation within 3 s\n"
               "    of both closure times, carried to them by the run's nodes): checked, contradicted (> 0.5 m / 5 deg);\n"
               "    the time offset between the run and the relations is found from the reference trajectory\n"
               "    (--reference, or reference.tum in RUN_DIR) when their time bases differ;\n"
               "  --reference: ATE/RPE against a TUM trajectory or a log with a reference (corrected CARMEN log,\n"
               "    or GPS: positions only), and loop closures classified true/false. Each false one is\n"
               "    weighed on its two keyframe scans (RUN_DIR/map.simplemap): PL-ICP started at the\n"
               "    reference's relative pose ends at the run's (verdict run), stays (reference) or neither.\n"
               "  relations_odometry.by_scans: the relation error by where both times fall among the run's scans (--scans):\n"
               "    at_scans, one_interval (inside one interval between two scans: odometry only), other; each\n"
               "    with n, abs_trans_mean_m and share_m (its error sum over all relations; the shares add up).\n"
               "  --truth: a simulated drive's folder (`urbanslam simulate`): its truth.tum is the reference, and\n"
               "    also map (distance of every point of RUN_DIR/map.ply, or without it of the keyframe scans of\n"
               "    map.simplemap, carried by the ATE's alignment, to the nearest true wall of walls.csv: source,\n"
               "    mean, median, p95, within_0_1_m, beyond_1_m)\n"
               "    loops_recall (revisited scans of loops.csv joined by an accepted closure within 2 s of both times)\n"
               "    and revisits_50m (revisits: runs of revisited scans with no gap over 1 s and at least 50 m of true path;\n"
               "    closed: those an accepted closure joined; unclosed: t_start, t_end and path_m of the others).\n"
               "Plots: RUN_DIR/eval_trajectory.png, RUN_DIR/eval_error.png.");
  ap.addPositional("RUN_DIR", "output folder of urbanslam run");
  ap.addOption("relations", "FILE", "Freiburg relations file (t1 t2 x y z roll pitch yaw)");
  ap.addOption("reference", "FILE", "reference trajectory: TUM file or a log that carries one");
  ap.addOption("truth", "SIM_DIR", "folder written by urbanslam simulate (truth.tum, walls.csv, loops.csv)");
  ap.addOption("scans", "FILE",
               "TUM file whose times are the scans the run placed, for the relations' breakdown (default: RUN_DIR/trajectory_scans.tum, "
               "else trajectory_keyframes.tum); give another run's to compare two runs on the same classes");
  ap.addOption("time-offset", "S", "seconds added to the run's timestamps for --relations (default: found)");
  ap.addOption("max-gap", "S",
               "a relation is used only when the trajectory poses around each of its times are at most this far apart [s]; 0: any gap",
               "0");
  ap.addOption("loop-tolerance-m", "M", "a closure is true when its measurement agrees with the reference within this", "0.5");
  ap.addOption("loop-tolerance-deg", "DEG", "... and this", "5");
  ap.addFlag("json", "print the figures as one JSON object");
  if (!ap.parse(args)) return 0;
  if (!ap.has("relations") && !ap.has("reference") && !ap.has("truth"))
    throw common::InputError("give --relations FILE, --reference FILE or --truth SIM_DIR");
  if (ap.has("reference") && ap.has("truth")) throw common::InputError("give --reference FILE or --truth SIM_DIR, not both");
  evaluation::RunReportOptions o;
  o.run_dir = ap.positional("RUN_DIR");
  if (ap.has("relations")) o.relations = ap.option("relations");
  if (ap.has("reference")) o.reference = ap.option("reference");
  if (ap.has("truth")) o.truth_dir = ap.option("truth");
  if (ap.has("scans")) o.scans = ap.option("scans");
  if (ap.has("time-offset")) o.time_offset_s = ap.optionDouble("time-offset");
  o.max_gap_s = ap.optionDouble("max-gap");
  if (!(o.max_gap_s >= 0)) throw common::InputError("--max-gap: must be a number of seconds >= 0");
  o.loop_tolerance_m = ap.optionDouble("loop-tolerance-m");
  o.loop_tolerance_deg = ap.optionDouble("loop-tolerance-deg");
  const evaluation::RunReport r = evaluation::evaluateRun(o);
  const fs::path dir = o.run_dir;
  // Plots: the aligned estimate over the reference, and the position error over time.
  if (!r.aligned.empty()) {
    laser_loop::PlotSeries ref{"reference", {}, {}, 0x808080}, est{"estimate (aligned)", {}, {}, 0x2060e0};
    for (const auto& p : r.reference) {
      ref.x.push_back(p.pose.x);
      ref.y.push_back(p.pose.y);
    }
    for (const auto& p : r.aligned) {
      est.x.push_back(p.pose.x);
      est.y.push_back(p.pose.y);
    }
    laser_loop::writePlotPng((dir / "eval_trajectory.png").string(), {{"trajectory vs reference", "x [m]", "y [m]", {ref, est}}});
    laser_loop::PlotSeries err{"position error", {}, r.errors_m, 0x2020c0};
    for (double t : r.times) err.x.push_back(t - (r.times.empty() ? 0 : r.times.front()));
    laser_loop::writePlotPng((dir / "eval_error.png").string(), {{"position error after alignment", "time [s]", "error [m]", {err}}});
  }
  if (ap.flag("json")) {
    std::cout << r.json.dump() << "\n";
  } else {
    std::cout << r.json.dump(2) << "\n";
  }
  return 0;
}

}  // namespace urbanslam::cli
