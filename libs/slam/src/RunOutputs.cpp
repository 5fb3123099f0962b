#include "urbanslam/slam/RunOutputs.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/AtomicFolder.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/PoseGraphIO.h"
#include "urbanslam/io/GridTiles.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MovingPoints.h"

namespace urbanslam::slam {

namespace fs = std::filesystem;

StagedMapFile::StagedMapFile(const std::string& dir, const Pipeline& pipeline, const std::vector<const Pipeline*>& separate) {
  const std::string target = dir + ".usmap";
  common::removeStaleTemporaries(target);
  if (pipeline.keyframes().empty()) return;
  std::error_code ec;
  const fs::path parent = fs::path(dir).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec) && !fs::create_directories(parent, ec))
    throw common::InputError(dir + ": cannot create the output folder (is its parent writable?)");
  path_ = common::temporaryPathFor(target);
  try {
    writeMapFile(pipeline, path_, separate);
  } catch (...) {
    // A constructor that throws runs no destructor: the half-written temporary goes now.
    fs::remove(path_, ec);
    throw;
  }
}

StagedMapFile::~StagedMapFile() {
  std::error_code ec;
  if (!path_.empty()) fs::remove(path_, ec);  // moved into the folder already, or a failed run's
}

namespace {

constexpr const char* kConfigHeader = "// Resolved configuration of this run";

// An earlier run's folder: its config.ini says so (extra files a bench added belong to that run).
bool isRunFolder(const std::string& dir) {
  return common::isReplaceableOutputFolder(dir, "config.ini", [](const std::string& first) { return first.rfind(kConfigHeader, 0) == 0; });
}

}  // namespace

void writePoseGraphG2o(const Pipeline& p, const std::string& path) {
  esdf::PoseGraph g;
  for (const auto& k : p.keyframes()) g.vertices.push_back({static_cast<long>(k.index), esdf::toVec(k.pose)});
  p.map().edges().forEach([&](const GraphEdge& e) {
    g.edges.push_back({static_cast<long>(e.from), static_cast<long>(e.to), esdf::toVec(e.measurement), e.information});
  });
  esdf::writePoseGraph(g, path, esdf::PoseGraphFormat::G2o);
}

common::Json writeRunOutputs(const Pipeline& p, const std::string& dir, const RunInfo& info) {
  using common::Json;
  // Everything goes into a staging folder that replaces `dir` at the end in one step: a run
  // folder never mixes two runs, and one killed while writing leaves the earlier run intact.
  common::AtomicFolder folder(dir, isRunFolder);
  const auto path = [&](const std::string& name) { return (fs::path(folder.stagingPath()) / name).string(); };
  const PipelineOptions& o = p.options();
  common::Stopwatch sw;

  // config.ini first: whoever looks at the outputs can see how they were made.
  {
    common::AtomicFile f(path("config.ini"));
    f.stream() << kConfigHeader << " (input: " << info.input_path
               << ", ini: " << (info.ini_path.empty() ? "built-in defaults" : info.ini_path) << ")\n"
               << info.resolved_ini;
    f.commit();
  }

  Json files = Json::array();
  std::vector<io::StampedPose> kf_traj;
  for (const auto& k : p.keyframes()) kf_traj.push_back({k.timestamp, k.pose});
  io::writeTum(path("trajectory_keyframes.tum"), kf_traj);
  files.push("trajectory_keyframes.tum");
  io::writeTum(path("trajectory_odometry.tum"), p.odometryTrajectory());
  files.push("trajectory_odometry.tum");
  io::writeTum(path("trajectory_scans.tum"), p.scanTrajectory());
  files.push("trajectory_scans.tum");
  if (const auto reference = p.referenceTrajectory(); !reference.empty()) {
    io::writeTum(path("reference.tum"), reference);
    files.push("reference.tum");
  }

  writePoseGraphG2o(p, path("pose_graph.g2o"));
  files.push("pose_graph.g2o");
  if (!info.map_file.empty()) {
    std::filesystem::rename(info.map_file, path(kMapFileName));  // beside the folder: the same file system
    files.push(kMapFileName);
  }
  {
    common::AtomicFile f(path("loop_closures.csv"));
    f.stream() << "from_keyframe,to_keyframe,from_time,to_time,detector,score,accepted,reason,x,y,phi,rms_m,mahalanobis2,gate_threshold,"
                  "free_space_conflict,prior_sigma_m,bearing_only,confirmed_by\n";
    char buf[512];
    p.loopClosureLog().forEach([&](const LoopClosureRecord& c) {
      std::snprintf(buf, sizeof buf, "%zu,%zu,%.6f,%.6f,%s,%.6g,%d,%s,%.6f,%.6f,%.6f,%.6g,%.6g,%.6g,%.4f,%.4g,%d,%s\n", c.from, c.to,
                    c.from_time, c.to_time, proposerName(c.detector), c.score, c.accepted ? 1 : 0, reasonName(c.reason), c.measurement.x,
                    c.measurement.y, c.measurement.phi, c.rms_m, c.mahalanobis2, c.gate_threshold, c.free_space_conflict, c.prior_sigma_m,
                    c.bearing_only ? 1 : 0, confirmationName(c.confirmed_by));
      f.stream() << buf;
    });
    f.commit();
    files.push("loop_closures.csv");
  }

  // The clouds are streamed from the keyframes, scan by scan: a city's cloud held whole would be
  // the largest thing in memory.
  const auto posed = p.posedKeyframes();
  const int decimation = o.map.point_decimation;
  const bool clouds = o.output.write_ply_binary || o.output.write_ply_ascii || o.output.write_pcd || o.output.write_xyz;
  MovingPointsResult moving;
  const bool remove_moving = clouds && o.map.remove_moving_points;
  if (remove_moving) moving = findMovingPoints(posed, o.map.movingPoints());
  const io::PointMask* mask = remove_moving ? &moving.static_points : nullptr;
  const size_t map_points = io::countMapPoints(posed, decimation, mask);
  if (o.output.write_ply_binary) {
    io::writePly(path("map.ply"), posed, decimation, io::PlyEncoding::BinaryLittleEndian, mask);
    files.push("map.ply");
  }
  if (o.output.write_ply_ascii) {
    io::writePly(path("map_ascii.ply"), posed, decimation, io::PlyEncoding::Ascii, mask);
    files.push("map_ascii.ply");
  }
  if (o.output.write_pcd) {
    io::writePcd(path("map.pcd"), posed, decimation, mask);
    files.push("map.pcd");
  }
  if (o.output.write_xyz) {
    io::writeXyz(path("map.xyz"), posed, decimation, mask);
    files.push("map.xyz");
  }
  if (o.output.write_simplemap) {
    io::writeSimpleMap(path("map.simplemap"), posed);
    files.push("map.simplemap");
  }
  Json grid = Json::object();
  if (o.output.write_grid && map_points > 0) {  // camera-only runs have no map points
    io::OccupancyGridOptions g;
    g.resolution_m = o.map.grid_resolution_m;
    g.max_cells = o.map.grid_max_cells;
    double resolution = g.resolution_m;
    const auto [w, h] = io::writeOccupancyGrid(path("grid"), posed, g, &resolution);
    grid["width"] = w;
    grid["height"] = h;
    grid["resolution_m"] = resolution;
    files.push("grid.png");
    files.push("grid.yaml");
    if (o.output.write_grid_tiles && resolution > g.resolution_m) {
      // grid.png is an overview: the map at the resolution asked for, a tile at a time.
      const auto tiles = io::writeOccupancyGridTiles(path("grid_tiles"), posed, g, o.map.grid_tile_cells);
      grid["tiles"] = tiles.size();
      grid["tile_cells"] = o.map.grid_tile_cells;
      grid["tiles_resolution_m"] = g.resolution_m;
      files.push("grid_tiles/");
    }
  }

  const PipelineStats& s = p.stats();
  Json j = Json::object();
  j["input"] = info.input_path;
  j["input_format"] = info.input_format;
  j["ini"] = info.ini_path;
  if (!info.resumed_map.empty()) j["resumed_map"] = info.resumed_map;
  if (info.sessions.type() != Json::Type::Null) j["sessions"] = info.sessions;
  if (info.separate_maps.type() != Json::Type::Null) j["separate_maps"] = info.separate_maps;
  j["estimator"] = p.estimatorName();
  Json& c = j["counts"];
  c["measurements"] = s.measurements;
  c["scans"] = s.scans;
  c["scans_used"] = s.scans_used;
  c["odometry"] = s.odometry;
  c["drive"] = s.drive;
  c["images"] = s.images;
  c["gps"] = s.gps;
  c["reference_poses"] = s.reference;
  c["keyframes"] = p.keyframes().size();
  c["map_points"] = map_points;
  c["map_points_moving"] = moving.moving;
  c["scan_matches_used"] = s.scan_matches_used;
  c["scan_matches_rejected"] = s.scan_matches_rejected;
  c["camera_motions_used"] = s.camera_motions_used;
  c["camera_motions_rejected"] = s.camera_motions_rejected;
  c["scans_anchored"] = s.scans_anchored;
  c["loop_closures_tried"] = s.closures_tried;
  c["loop_closures_accepted"] = s.closures_accepted;
  c["loop_closures_rejected"] = s.closures_rejected;
  size_t camera_confirmed = 0;
  p.loopClosureLog().forEach([&](const LoopClosureRecord& r) { camera_confirmed += r.confirmed_by == Confirmation::Camera; });
  c["loop_closures_camera_confirmed"] = camera_confirmed;
  // Factorisations of the whole map (full recoveries, exact covariances): the work that grows with
  // it. This run's only: a resumed map's earlier sessions are not counted.
  c["map_factorisations"] = p.map().filter() ? p.map().filter()->factorisations() : 0;
  // Poses in the filter: one per keyframe, fewer where keyframes hang from others' (a reduced
  // pose graph).
  c["filter_poses"] = p.map().filter() ? p.map().filter()->size() : 0;
  c["image_keyframes"] = s.image_keyframes;
  c["image_proposals"] = s.image_proposals;
  Json& t = j["timing"];
  const double duration = s.last_timestamp - s.first_timestamp;
  t["wall_s"] = s.wall_s;
  t["log_duration_s"] = duration;
  t["real_time_factor"] = s.wall_s > 0 ? duration / s.wall_s : 0.0;
  t["step_ms_p50"] = s.step_ms.percentile(50);
  t["step_ms_p99"] = s.step_ms.percentile(99);
  t["step_ms_max"] = s.step_ms.percentile(100);
  Json by = Json::object();
  for (size_t k = 0; k < s.step_ms_by_decade.size(); ++k)
    if (!s.step_ms_by_decade[k].empty()) by["1e" + std::to_string(k)] = s.step_ms_by_decade[k].percentile(99);
  t["step_ms_p99_by_keyframes"] = std::move(by);
  t["keyframe_ms_p50"] = s.keyframe_ms.percentile(50);
  t["keyframe_ms_p99"] = s.keyframe_ms.percentile(99);
  t["loop_search_ms_p50"] = s.closure_ms.percentile(50);
  t["loop_search_ms_p99"] = s.closure_ms.percentile(99);
  // Closure → corrected map, as the front end sees it (queue included on the global thread).
  t["global_latency_ms_p50"] = s.global_latency_ms.percentile(50);
  t["global_latency_ms_p99"] = s.global_latency_ms.percentile(99);
  t["global_backlog_max"] = s.global_backlog_max;
  t["global_wait_s"] = s.global_wait_s;
  t["outputs_s"] = sw.seconds();
  t["moving_points_s"] = moving.seconds;
  t["peak_rss_mb"] = static_cast<double>(common::peakResidentBytes()) / (1024.0 * 1024.0);
  // The keyframe scans: held in memory (bounded by [map] scan_cache_mb) and spilled to disk.
  Json scans = Json::object();
  scans["resident_mb"] = static_cast<double>(p.map().scans().residentBytes()) / (1024.0 * 1024.0);
  scans["spilled_mb"] = static_cast<double>(p.map().scans().spilledBytes()) / (1024.0 * 1024.0);
  scans["cache_mb"] = static_cast<double>(p.map().scans().cacheBytes()) / (1024.0 * 1024.0);
  j["scan_store"] = std::move(scans);
  if (grid.size() > 0) j["grid"] = grid;
  j["files"] = files;
  j["config"] = optionsToJson(o);
  common::writeTextAtomically(path("stats.json"), j.dump(2) + "\n");
  folder.commit();
  return j;
}

}  // namespace urbanslam::slam
