#include "urbanslam/evaluation/RunReport.h"

#include <filesystem>
#include <limits>

#include "urbanslam/common/Error.h"
#include "urbanslam/evaluation/ClosureEvidence.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/evaluation/MapAccuracy.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::evaluation {

namespace fs = std::filesystem;

namespace {

// A reference trajectory from a TUM file or from any log that carries one (reference poses of a
// corrected CARMEN log, or GPS fixes: positions only).
std::vector<io::StampedPose> loadReference(const std::string& path, bool& positions_only) {
  positions_only = false;
  const auto ext = fs::path(path).extension().string();
  if (ext == ".tum" || ext == ".txt") {
    auto poses = io::readTum(path);
    if (poses.empty()) throw common::InputError(path + ": no poses (an empty trajectory cannot be a reference)");
    return poses;
  }
  auto src = io::openDataSource(path);
  std::vector<io::StampedPose> ref, gps;
  io::Measurement m;
  while (src->next(m)) {
    if (auto* r = std::get_if<io::ReferencePose>(&m)) ref.push_back({r->timestamp, r->pose});
    if (auto* g = std::get_if<io::GpsFix>(&m)) gps.push_back({g->timestamp, {g->x_m, g->y_m, 0}});
  }
  if (!ref.empty()) return ref;
  if (!gps.empty()) {
    positions_only = true;
    return gps;
  }
  throw common::InputError(path + ": carries no reference trajectory (no reference poses, no GPS)");
}

// One closure that disagrees with a reference (the corrected log's poses or the relations).
common::Json closureJson(const FalseClosure& f) {
  common::Json e = common::Json::object();
  e["from_keyframe"] = f.from_keyframe;
  e["to_keyframe"] = f.to_keyframe;
  e["from_time"] = f.from_time;
  e["to_time"] = f.to_time;
  e["error_m"] = f.error_m;
  e["error_deg"] = f.error_deg;
  return e;
}

common::Json poseJson(const common::Pose2& p) {
  common::Json j = common::Json::object();
  j["x"] = p.x;
  j["y"] = p.y;
  j["phi"] = p.phi;
  return j;
}

// The map against the simulated city's walls, and the share of true revisits closed. `truth`: the
// drive's truth.tum, already read as the run's reference.
void evaluateAgainstSimulation(const fs::path& run, const fs::path& sim, const std::vector<io::StampedPose>& truth,
                               const common::Pose2& to_truth, common::Json& j) {
  // The map as the run exported it (map.ply: moving things left out), or else every point of
  // the keyframes' scans.
  const fs::path ply = run / "map.ply", simplemap = run / "map.simplemap";
  std::vector<io::MapPoint> points;
  const bool from_ply = fs::exists(ply);
  if (from_ply) {
    points = io::readPly(ply.string());
  } else if (fs::exists(simplemap)) {
    const auto keyframes = io::readSimpleMap(simplemap.string());
    std::vector<io::PosedScan> posed;
    for (const auto& k : keyframes) posed.push_back({k.pose, &k.scan});
    points = io::mapPoints(posed);
  } else {
    throw common::InputError(run.string() + ": neither map.ply nor map.simplemap (the map is scored on one of them; [output])");
  }
  const auto acc = mapAccuracy(points, to_truth, readWallsCsv((sim / "walls.csv").string()));
  common::Json m = common::Json::object();
  m["source"] = from_ply ? "map.ply" : "map.simplemap";
  m["points"] = acc.points;
  m["mean_m"] = acc.mean_m;
  m["median_m"] = acc.median_m;
  m["p95_m"] = acc.p95_m;
  m["within_0_1_m"] = acc.within_0_1_m;
  m["beyond_1_m"] = acc.beyond_1_m;
  j["map"] = std::move(m);
  if (fs::exists(run / "loop_closures.csv")) {
    const auto closures = readLoopClosuresCsv((run / "loop_closures.csv").string());
    const auto loops = readTrueLoopsCsv((sim / "loops.csv").string());
    const auto r = loopRecall(closures, loops);
    common::Json l = common::Json::object();
    l["revisited_scans"] = r.revisited_scans;
    l["closed_scans"] = r.closed_scans;
    l["recall"] = r.recall;
    j["loops_recall"] = std::move(l);
    const auto v = revisitRecall(closures, loops, truth);
    common::Json rv = common::Json::object();
    rv["revisits"] = v.revisits;
    rv["closed"] = v.closed;
    common::Json unclosed = common::Json::array();
    for (const auto& u : v.unclosed) {
      common::Json e = common::Json::object();
      e["t_start"] = u.t_start;
      e["t_end"] = u.t_end;
      e["path_m"] = u.path_m;
      unclosed.push(std::move(e));
    }
    rv["unclosed"] = std::move(unclosed);
    j["revisits_50m"] = std::move(rv);
  }
}

}  // namespace

RunReport evaluateRun(const RunReportOptions& o) {
  const bool with_truth = !o.truth_dir.empty();
  const fs::path truth_dir = o.truth_dir;
  const std::string reference_path = with_truth ? (truth_dir / "truth.tum").string() : o.reference;
  const double max_gap = o.max_gap_s > 0 ? o.max_gap_s : std::numeric_limits<double>::infinity();
  const fs::path dir = o.run_dir;
  const fs::path traj_path = dir / "trajectory_odometry.tum", nodes_path = dir / "trajectory_scans.tum";
  if (!fs::exists(traj_path)) throw common::InputError(traj_path.string() + ": missing (not a run folder?)");
  const auto estimate = io::readTum(traj_path.string());
  if (estimate.empty()) throw common::InputError(traj_path.string() + ": no poses (the run mapped nothing)");
  // The relations score the run's nodes, the scans it placed (as Cartographer scores its own),
  // at each relation time: bridged along the trajectory at odometry times between nodes, which
  // where every relation time is a scan time (the raw benchmark logs) is Cartographer's figure
  // to the digit, and on sparse scans keeps the turns the odometry saw. A folder without nodes
  // (a peer's) is scored on its one trajectory.
  const bool have_nodes = fs::exists(nodes_path);
  const auto nodes = have_nodes ? io::readTum(nodes_path.string()) : estimate;

  RunReport report;
  common::Json& j = report.json;
  j = common::Json::object();
  j["run"] = dir.string();
  bool positions_only = false;
  std::vector<io::StampedPose> reference;
  if (!reference_path.empty())
    reference = loadReference(reference_path, positions_only);
  else if (fs::exists(dir / "reference.tum"))
    reference = io::readTum((dir / "reference.tum").string());

  if (!o.relations.empty()) {
    const auto rel = readRelations(o.relations);
    double offset = 0;
    if (o.time_offset_s)
      offset = *o.time_offset_s;
    else {
      std::vector<double> log_times;  // the log's own timestamps (not estimated values)
      for (const auto& p : estimate) log_times.push_back(p.timestamp);
      offset = findRelationTimeOffset(reference.empty() ? estimate : reference, rel, log_times);
    }
    const auto block = [&](const std::vector<io::StampedPose>& traj, const fs::path& path) {
      const auto m = relationMetrics(traj, rel, offset, max_gap);
      common::Json r = common::Json::object();
      r["file"] = o.relations;
      r["trajectory"] = path.filename().string();
      r["used"] = m.used;
      r["skipped"] = m.skipped;
      r["time_offset_s"] = offset;
      r["abs_trans_mean_m"] = m.abs_trans_m.mean;
      r["abs_trans_std_m"] = m.abs_trans_m.std;
      r["sqr_trans_mean_m2"] = m.sqr_trans_m2.mean;
      r["sqr_trans_std_m2"] = m.sqr_trans_m2.std;
      r["abs_rot_mean_deg"] = m.abs_rot_deg.mean;
      r["abs_rot_std_deg"] = m.abs_rot_deg.std;
      r["sqr_rot_mean_deg2"] = m.sqr_rot_deg2.mean;
      r["sqr_rot_std_deg2"] = m.sqr_rot_deg2.std;
      if (m.used == 0) throw common::InputError(o.relations + ": no relation falls inside the run's time span (wrong dataset or offset?)");
      return r;
    };
    j["relations"] = block(have_nodes ? bridgeNodes(nodes, estimate) : estimate, have_nodes ? nodes_path : traj_path);
    j["relations"]["interpolation"] = have_nodes ? "odometry" : "linear";
    if (have_nodes) {
      j["relations_linear"] = block(nodes, nodes_path);  // the nodes' chords, as Cartographer interpolates
      j["relations_linear"]["interpolation"] = "linear";
      j["relations_odometry"] = block(estimate, traj_path);
    }
    common::Json& r = j[have_nodes ? "relations_odometry" : "relations"];
    // Where the odometry-time trajectory's error comes from: relations at scans, inside one
    // interval between scans (only the odometry there), and the rest; the three shares add up to
    // its abs_trans_mean_m.
    fs::path scans_path = !o.scans.empty() ? fs::path(o.scans) : nodes_path;
    if (o.scans.empty() && !fs::exists(scans_path)) scans_path = dir / "trajectory_keyframes.tum";
    if (fs::exists(scans_path) || !o.scans.empty()) {
      std::vector<double> scan_times;
      for (const auto& p : io::readTum(scans_path.string())) scan_times.push_back(p.timestamp);
      const auto by = relationsByScans(estimate, rel, offset, scan_times, max_gap);
      common::Json& b = r["by_scans"];
      b["scans"] = scans_path.string();
      const auto cls = [](const RelationClass& c) {
        common::Json o = common::Json::object();
        o["n"] = c.n;
        o["abs_trans_mean_m"] = c.abs_trans_mean_m;
        o["share_m"] = c.share_m;
        return o;
      };
      b["at_scans"] = cls(by.at_scans);
      b["one_interval"] = cls(by.one_interval);
      b["other"] = cls(by.other);
    }
    // The run's accepted closures against the relations (independent of any corrected log),
    // carried over the short legs by the odometry-time trajectory (it follows the turns between
    // sparse scans; at the scans it is their poses).
    if (fs::exists(dir / "loop_closures.csv")) {
      const auto lc = checkLoopsWithRelations(readLoopClosuresCsv((dir / "loop_closures.csv").string()), estimate, rel, offset);
      common::Json& l = j["relations"]["loops"];
      l["accepted"] = lc.accepted;
      l["checked"] = lc.checked;
      l["contradicted"] = lc.contradicted;
      common::Json list = common::Json::array();
      for (const auto& f : lc.contradictions) list.push(closureJson(f));
      l["contradicted_list"] = std::move(list);
    }
    if (!reference.empty()) {
      const auto mr = relationMetrics(reference, rel, offset, 5.0);  // reference poses are sparse
      j["relations"]["reference_abs_trans_mean_m"] = mr.abs_trans_m.mean;
      j["relations"]["reference_abs_rot_mean_deg"] = mr.abs_rot_deg.mean;
    }
  }
  if (!reference_path.empty()) {
    const auto tm = trajectoryMetrics(estimate, reference, positions_only, positions_only ? 2.0 : 1.0);
    if (tm.matched == 0)
      throw common::InputError(reference_path + ": no reference pose falls inside the run's time span (" + traj_path.string() +
                               "): wrong dataset?");
    j["reference"] = reference_path;
    if (with_truth) evaluateAgainstSimulation(dir, truth_dir, reference, tm.alignment, j);
    j["positions_only"] = positions_only;
    j["matched"] = tm.matched;
    j["ate_rmse_m"] = tm.ate_rmse_m;
    j["ate_max_m"] = tm.ate_max_m;
    j["rpe_trans_rmse_m"] = tm.rpe_trans_rmse_m;
    j["rpe_rot_rmse_deg"] = tm.rpe_rot_rmse_deg;
    if (fs::exists(dir / "loop_closures.csv")) {
      const auto lm = classifyLoopClosures(readLoopClosuresCsv((dir / "loop_closures.csv").string()), reference, positions_only,
                                           o.loop_tolerance_m, o.loop_tolerance_deg);
      j["loops_accepted"] = lm.accepted;
      j["loops_true"] = lm.true_positive;
      j["loops_false"] = lm.false_positive;
      j["loops_unverifiable"] = lm.unverifiable;
      // The keyframe scans (map.simplemap) say whether each false closure or the reference is
      // what they support; a positions-only reference (GPS) has no relative pose to test.
      std::vector<io::KeyframeScan> keyframes;
      const fs::path simplemap = dir / "map.simplemap";
      const bool weigh = !positions_only && !lm.false_closures.empty() && fs::exists(simplemap);
      if (weigh) keyframes = io::readSimpleMap(simplemap.string());
      size_t favour_run = 0, favour_reference = 0;
      common::Json list = common::Json::array();
      for (const auto& f : lm.false_closures) {
        common::Json e = closureJson(f);
        const auto in_map = [&](long k) { return k >= 0 && static_cast<size_t>(k) < keyframes.size(); };
        if (weigh && in_map(f.from_keyframe) && in_map(f.to_keyframe)) {
          const auto ev = weighClosure(keyframes[static_cast<size_t>(f.from_keyframe)].scan,
                                       keyframes[static_cast<size_t>(f.to_keyframe)].scan, f.measurement, f.reference);
          common::Json s = common::Json::object();
          s["verdict"] = ev.verdict;
          s["from_reference"] = poseJson(ev.from_reference);
          s["matched_fraction"] = ev.matched_fraction;
          s["run_conflict"] = ev.run_conflict;
          s["reference_conflict"] = ev.reference_conflict;
          e["scans"] = std::move(s);
          favour_run += ev.verdict == "run" ? 1 : 0;
          favour_reference += ev.verdict == "reference" ? 1 : 0;
        }
        list.push(std::move(e));
      }
      j["loops_false_list"] = std::move(list);
      if (weigh) {
        j["loops_false_scans_favour_run"] = favour_run;
        j["loops_false_scans_favour_reference"] = favour_reference;
      } else if (!positions_only && !lm.false_closures.empty()) {
        j["loops_false_scans_skipped"] = "no map.simplemap in RUN_DIR ([output] write_simplemap = false)";
      }
    }
    report.reference = reference;
    report.aligned = tm.aligned;
    report.times = tm.times;
    report.errors_m = tm.errors_m;
  }
  return report;
}

}  // namespace urbanslam::evaluation
