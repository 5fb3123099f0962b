#include "urbanslam/sim/SimulationOutputs.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/RawlogWriter.h"
#include "urbanslam/sim/ImageLoopTruth.h"
#include "urbanslam/sim/LoopTruth.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/sim/WallsOutput.h"

namespace urbanslam::sim {

SimulationSummary writeSimulation(const SimOptions& options, const std::string& dir, const std::string& resolved_ini,
                                  const std::function<void(double)>& progress, bool write_rawlog) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw common::InputError(dir + ": cannot create the output folder (" + ec.message() + ")");

  SimulationSummary sum;
  SimulatedSource source(options);
  const bool camera = options.camera.enabled;
  std::unique_ptr<io::RawlogWriter> rawlog;
  if (write_rawlog)
    rawlog = std::make_unique<io::RawlogWriter>(dir + "/city.rawlog", io::RawlogLayout::Observations, 5,
                                                camera ? io::ImageStorage::External : io::ImageStorage::Embedded);
  common::AtomicFile loops(dir + "/loops.csv");
  loops.stream() << "t_old,t_new,overlap,distance_m\n";
  LoopTruthFinder finder(options.loops);
  // Image loop truth: views that see the same wall points (ImageLoopTruth.h), pointing within
  // image_max_heading_deg (from the other side of a thin object, or along a wall from the other
  // end, points are shared without the images looking alike).
  std::unique_ptr<common::AtomicFile> image_loops;
  if (camera) {
    image_loops = std::make_unique<common::AtomicFile>(dir + "/image_loops.csv");
    image_loops->stream() << "t_old,t_new,overlap,distance_m\n";
  }
  std::unique_ptr<ImageLoopTruth> image_finder;
  if (camera) {
    std::vector<double> bearings(static_cast<size_t>(options.camera.width_px));
    for (size_t x = 0; x < bearings.size(); ++x) bearings[x] = source.camera()->columnBearing(static_cast<int>(x));
    image_finder = std::make_unique<ImageLoopTruth>(options.loops, std::move(bearings));
  }
  std::map<double, std::string> image_at;                                     // time -> image name
  std::vector<std::pair<std::string, std::vector<std::string>>> image_truth;  // eval-image-loop format
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
    if (rawlog) rawlog->write(m);
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
    } else if (const auto* img = std::get_if<io::CameraImage>(&m)) {
      ++sum.images;
      if (have_truth) {  // yielded with the image's reference pose just before it
        const common::Pose2 cam = common::compose(last_truth, cameraMount(options.camera));
        // The image file's name without the extension (LABEL_000123), as the rawlog names it; the
        // same without a rawlog, so image_loops.txt does not depend on writing one.
        std::snprintf(buf, sizeof buf, "_%06zu", sum.images - 1);
        std::string name = rawlog ? rawlog->lastImageFile() : img->label + buf;
        name = name.substr(0, name.rfind('.'));
        image_at[img->timestamp] = name;
        std::vector<std::string> matches;
        for (const LoopPair& p : image_finder->add(img->timestamp, cam, source.camera()->columnRanges(cam))) {
          const auto old = image_at.find(p.t_old);
          if (old == image_at.end()) continue;
          std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.4f,%.3f\n", p.t_old, p.t_new, p.overlap, p.distance_m);
          image_loops->stream() << buf;
          ++sum.image_loop_pairs;
          matches.push_back(old->second);
        }
        if (!matches.empty()) image_truth.emplace_back(name, std::move(matches));
      }
    } else if (std::holds_alternative<io::OdometryReading>(m)) {
      ++sum.odometry;
    } else if (std::holds_alternative<io::GpsFix>(m)) {
      ++sum.gps;
    }
    if (progress && k % 256 == 0) progress(source.progress());
  }
  if (rawlog) rawlog->close();
  loops.commit();
  if (image_loops) {
    image_loops->commit();
    common::AtomicFile gt(dir + "/image_loops.txt");
    gt.stream() << "# urbanslam simulate: for each image that closes a loop, the earlier images showing the same\n"
                   "# place (images in city_Images/; the pairs of image_loops.csv). For eval-image-loop --gt.\n";
    for (const auto& [query, matches] : image_truth) {
      gt.stream() << query;
      for (const auto& m2 : matches) gt.stream() << ' ' << m2;
      gt.stream() << '\n';
    }
    gt.commit();
    sum.loop_images = image_truth.size();
  }
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
  sum.render_wall_s = source.renderSeconds();
  sum.total_wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return sum;
}

}  // namespace urbanslam::sim
