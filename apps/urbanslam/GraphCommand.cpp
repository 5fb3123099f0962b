// `urbanslam graph`: the ESDF as a pose-graph back end. Feeds a g2o / TORO graph to the filter
// incrementally in vertex order (odometry edges as prediction with augmentation, the others as
// observations), then reports the final chi2 (g2o/MRPT convention) and timings.
#include <iostream>
#include <sstream>
#include <string>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseGraphBackend.h"
#include "urbanslam/esdf/PoseGraphIO.h"

namespace urbanslam::cli {
namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int graphCommand(const Argv& args) {
  ArgParser ap("urbanslam graph IN [--out OUT.g2o] [--stats FILE.json] [--json] [options]",
               "Runs the ESDF (exactly sparse delayed-state filter) over a 2D pose graph, g2o (VERTEX_SE2 /\n"
               "EDGE_SE2, vertices optional) or TORO (VERTEX2 / EDGE2), plain or .gz. Poses are added in id\n"
               "order: the edge from the previous pose is a prediction with augmentation, every other edge to\n"
               "an earlier pose a relative-pose observation. Prints the final chi2 = sum e' Omega e (g2o/MRPT\n"
               "convention) and timings.");
  ap.addPositional("IN", "pose graph (.g2o, .graph, optionally .gz)");
  ap.addOption("out", "OUT", "write the optimised graph (TORO when OUT ends in .graph, else g2o)");
  ap.addOption("stats", "FILE.json", "write statistics (the --json object, pretty-printed) to FILE.json");
  ap.addFlag("json", "print one JSON object on stdout instead of text");
  ap.addFlag("gate", "gate loop closures with the chi2 test (rejected edges still count in chi2)");
  ap.addOption("gate-probability", "P", "chi2 quantile probability of the gate", "0.999");
  ap.addOption("gate-covariance", "MODE", "exact (refactorise when stale) or conservative (last factorisation + dead reckoning)", "exact");
  ap.addFlag("no-relinearise", "linearise every edge once, as the thesis filter does");
  ap.addOption("full-every", "N", "full recovery after N loop closures", "20");
  ap.addOption("innovation-chi2", "X", "full recovery at once after a closure with innovation chi2 above X", "50");
  ap.addOption("min-gap", "F", "full recoveries at least F * poses apart (amortises their cost)", "0.25");
  ap.addOption("heading-innovation", "RAD", "full recovery (whatever --min-gap says) before a closure whose heading innovation exceeds RAD",
               "1.0");
  ap.addFlag("no-headings-first",
             "that recovery takes Gauss-Newton steps from the stale estimate only (no headings-first solve; branches re-chosen)");
  ap.addOption("window", "W", "poses re-solved by the partial recovery after other loop closures", "50");
  ap.addEpilog(
      "Example:\n  urbanslam graph manhattan.g2o --out manhattan_opt.g2o --json\n"
      "JSON keys: chi2, poses, edges, time_s (read + filter), read_s, filter_s, step_ms_p50,\n"
      "step_ms_p99 (per-edge processing time), full_recoveries, partial_recoveries, rejected_edges, ...");
  if (!ap.parse(args)) return 0;

  esdf::PoseGraphBackendOptions o;
  o.gate_loop_closures = ap.flag("gate");
  o.filter.chi2_gate_probability = ap.optionDouble("gate-probability");
  if (!(o.filter.chi2_gate_probability > 0 && o.filter.chi2_gate_probability < 1))
    throw common::InputError("--gate-probability: must be in (0, 1)");
  const std::string gate_cov = ap.option("gate-covariance");
  if (gate_cov == "exact")
    o.filter.gate_covariance = esdf::CovarianceMode::Exact;
  else if (gate_cov == "conservative")
    o.filter.gate_covariance = esdf::CovarianceMode::Conservative;
  else
    throw common::InputError("--gate-covariance: '" + gate_cov + "' is not one of exact|conservative");
  o.filter.relinearise = !ap.flag("no-relinearise");
  o.full_recovery_every_closures = static_cast<int>(ap.optionInt("full-every"));
  o.full_recovery_innovation_chi2 = ap.optionDouble("innovation-chi2");
  o.full_recovery_min_gap_fraction = ap.optionDouble("min-gap");
  o.recent_window_poses = static_cast<int>(ap.optionInt("window"));
  if (ap.flag("no-headings-first")) {
    o.reinitialise_from_headings = false;
    o.filter.commit_heading_branch = false;
  }
  o.full_recovery_heading_innovation_rad = ap.optionDouble("heading-innovation");
  if (!(o.full_recovery_heading_innovation_rad > 0)) throw common::InputError("--heading-innovation: must be > 0");
  if (o.full_recovery_every_closures < 1) throw common::InputError("--full-every: must be >= 1");
  if (o.recent_window_poses < 0) throw common::InputError("--window: must be >= 0");
  if (o.full_recovery_min_gap_fraction < 0) throw common::InputError("--min-gap: must be >= 0");

  const std::string in = ap.positional("IN");
  common::Stopwatch total;
  const esdf::PoseGraph graph = esdf::readPoseGraph(in);
  const double read_s = total.seconds();
  const esdf::PoseGraphBackendResult r = esdf::runPoseGraphBackend(graph, o);
  const double time_s = total.seconds();

  if (ap.has("out")) {
    const std::string out = ap.option("out");
    esdf::writePoseGraph(esdf::withPoses(graph, r), out,
                         endsWith(out, ".graph") ? esdf::PoseGraphFormat::Toro : esdf::PoseGraphFormat::G2o);
  }

  common::Json j = common::Json::object();
  j["input"] = in;
  j["chi2"] = r.chi2;
  j["poses"] = r.poses.size();
  j["edges"] = r.edges;
  j["time_s"] = time_s;
  j["read_s"] = read_s;
  j["filter_s"] = r.time_s;
  j["recovery_s"] = r.recovery_s;
  j["step_ms_p50"] = common::percentile(r.step_ms, 50);
  j["step_ms_p90"] = common::percentile(r.step_ms, 90);
  j["step_ms_p99"] = common::percentile(r.step_ms, 99);
  j["step_ms_max"] = common::percentile(r.step_ms, 100);
  j["augment_edges"] = r.augment_edges;
  j["observation_edges"] = r.observation_edges;
  j["rejected_edges"] = r.rejected_edges;
  j["full_recoveries"] = r.full_recoveries;
  j["partial_recoveries"] = r.partial_recoveries;
  j["factors_relinearised"] = r.factors_relinearised;
  j["final_relinearise_passes"] = r.final_relinearise_passes;
  j["heading_triggered_recoveries"] = r.heading_triggered_recoveries;
  j["large_heading_innovations"] = r.large_heading_innovations;
  j["converged"] = r.converged;
  j["relinearise"] = o.filter.relinearise;
  j["gate"] = o.gate_loop_closures;
  j["memory_bytes"] = r.memory_bytes;
  j["memory_bytes_per_pose"] = r.poses.empty() ? 0.0 : static_cast<double>(r.memory_bytes) / r.poses.size();
  j["peak_rss_bytes"] = common::peakResidentBytes();

  if (ap.has("stats")) common::writeTextAtomically(ap.option("stats"), j.dump(2) + "\n");
  if (ap.flag("json")) {
    std::cout << j.dump() << "\n";
  } else {
    std::ostringstream s;
    s << in << ": " << r.poses.size() << " poses, " << r.edges << " edges (" << r.observation_edges << " observations";
    if (o.gate_loop_closures) s << ", " << r.rejected_edges << " rejected by the gate";
    s << ")\n";
    s.precision(10);
    s << "chi2 " << r.chi2 << "\n";
    s.precision(4);
    s << "time " << time_s << " s (read " << read_s << " s, filter " << r.time_s << " s, of which full recovery " << r.recovery_s
      << " s); per edge p50 " << common::percentile(r.step_ms, 50) << " ms, p99 " << common::percentile(r.step_ms, 99) << " ms\n";
    s << r.full_recoveries << " full / " << r.partial_recoveries << " partial recoveries, " << r.factors_relinearised
      << " relinearised factors" << (r.converged || !o.filter.relinearise ? "" : " (relinearisation not converged)") << "\n";
    if (ap.has("out")) s << "wrote " << ap.option("out") << "\n";
    std::cout << s.str();
  }
  return 0;
}

}  // namespace urbanslam::cli
