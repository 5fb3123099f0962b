// Kidnapping in a simulated city, with and without the camera: the drive's first half mapped by
// the pipeline (laser + camera, the ini's [loop_closure] image_detector keeping the keyframes'
// image words), its second half localized uninterrupted from the pose where the map ended (the
// jumps start and end at scans that run tracked without the camera), then spliced as kidnap.py splices a CARMEN log: --before seconds up to
// a time T1, then --after seconds from a later time T2 (--gap s later, --min-jump-m away, both tracked by the reference), the second
// piece's timestamps moved back to follow T1 and its odometry moved to continue from T1's. Each spliced stream is localized twice, the
// images used and ignored (ImagePlaceOptions::enabled); a jump is relocalised at the first tracked pose within
// --tolerance-m / --tolerance-deg of the simulator's true pose of the same scan (in the map's
// frame, by the first keyframe). Prints one JSON object: the uninterrupted second half with and
// without the camera (tracked scans, fixes, fixes away from the truth), the jumps, and per mode
// relocalised, within_3s, the median time and the fixes away from the truth.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/evaluation/Kidnapping.h"
#include "urbanslam/io/MemorySource.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/PipelineOptions.h"

using namespace urbanslam;

namespace {

bool usable(const io::Measurement& m) {
  // The localizer reads scans, odometry and images; the truth it must not see.
  return std::holds_alternative<io::LaserScan>(m) || std::holds_alternative<io::OdometryReading>(m) ||
         std::holds_alternative<io::CameraImage>(m);
}

std::vector<slam::LocalizedScan> localize(const slam::Pipeline& map, const std::vector<io::Measurement>& stream,
                                          const common::Pose2& initial, bool images, slam::LocalizerStats* stats = nullptr) {
  slam::LocalizerOptions o = slam::localizerOptions(map.options());
  o.images.enabled = images;
  slam::Localizer loc(map.map(), map.options(), o);
  loc.setInitialPose(initial);
  io::MemorySource source(stream);
  std::vector<slam::LocalizedScan> scans = slam::localizeInMaps({&loc}, source, nullptr, &map.options()).scans;
  if (stats) *stats = loc.stats();
  return scans;
}

double arg(int argc, char** argv, const std::string& name, double fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (argv[i] == "--" + name) return std::stod(argv[i + 1]);
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  std::string city, ini = std::string(URBANSLAM_SOURCE_DIR) + "/ini/default.ini";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << "usage: city_kidnap --city CITY_INI [--ini PIPELINE_INI] [--count N] [--before S] [--after S] [--gap S]\n"
                   "                   [--min-jump-m M] [--tolerance-m M] [--tolerance-deg D]\n"
                   "Kidnappings in a simulated city's second half, localized in its first half's map with and without\n"
                   "the camera; prints one JSON object.\n";
      return 0;
    }
    if (a == "--city" && i + 1 < argc) city = argv[i + 1];
    if (a == "--ini" && i + 1 < argc) ini = argv[i + 1];
  }
  if (city.empty()) {
    std::cerr << "city_kidnap: --city CITY_INI is required\n";
    return 2;
  }
  const int count = static_cast<int>(arg(argc, argv, "count", 10));
  const double before = arg(argc, argv, "before", 10), after = arg(argc, argv, "after", 20), gap = arg(argc, argv, "gap", 30);
  const double min_jump = arg(argc, argv, "min-jump-m", 5), tol_m = arg(argc, argv, "tolerance-m", 0.5);
  const double tol_rad = arg(argc, argv, "tolerance-deg", 10) * M_PI / 180;
  try {
    slam::PipelineOptions options = slam::loadPipelineOptions(ini, nullptr);
    slam::resolveDefaultPaths(options, URBANSLAM_SOURCE_DIR);
    sim::SimulatedSource sim(sim::loadSimOptions(city));
    std::vector<io::Measurement> all;
    std::vector<io::StampedPose> truth;  // the simulator's pose at every scan and image, in time order
    size_t scans = 0;
    for (io::Measurement m; sim.next(m);) {
      if (const auto* r = std::get_if<io::ReferencePose>(&m)) truth.push_back({r->timestamp, r->pose});
      if (usable(m)) scans += std::holds_alternative<io::LaserScan>(m), all.push_back(std::move(m));
    }
    const auto truthAt = [&](double t) -> std::optional<common::Pose2> {
      const auto it =
          std::lower_bound(truth.begin(), truth.end(), t - 1e-4, [](const io::StampedPose& p, double v) { return p.timestamp < v; });
      if (it == truth.end() || std::abs(it->timestamp - t) > 1e-3) return std::nullopt;
      return it->pose;
    };
    // The first half (up to the middle scan) mapped.
    size_t half = 0;
    for (size_t seen = 0; half < all.size() && seen < scans / 2; ++half) seen += std::holds_alternative<io::LaserScan>(all[half]);
    slam::Pipeline map(options);
    {
      const std::vector<io::Measurement> first_half(all.begin(), all.begin() + static_cast<long>(half));
      io::MemorySource first(first_half);
      map.run(first);
      map.finish();
    }
    const std::vector<io::Measurement> second(all.begin() + static_cast<long>(half), all.end());
    all.clear();
    // The map's frame against the truth's, from the first keyframe (the map's error, a tenth of
    // a metre, is well within the tolerance).
    const slam::Keyframe& k0 = map.keyframes().front();
    const auto g0 = truthAt(k0.timestamp);
    if (!g0) throw common::InputError(city + ": no true pose at the first keyframe");
    const common::Pose2 map_from_truth = common::compose(k0.pose, common::inverse(*g0));
    const auto trueAt = [&](double t) -> std::optional<common::Pose2> {
      const auto g = truthAt(t);
      return g ? std::optional<common::Pose2>(common::compose(map_from_truth, *g)) : std::nullopt;
    };
    const auto close = [&](const common::Pose2& a, const common::Pose2& b) {
      return std::hypot(a.x - b.x, a.y - b.y) <= tol_m && std::abs(common::wrapToPi(a.phi - b.phi)) <= tol_rad;
    };
    const common::Pose2 start = map.scanTrajectory().back().pose;
    // The second half uninterrupted, without and with the camera: tracked share, fixes, and the
    // fixes away from the truth. The jumps are picked among the scans tracked without it within
    // the tolerance of the truth.
    common::Json uninterrupted = common::Json::object();
    std::vector<slam::LocalizedScan> ref;
    for (const bool images : {false, true}) {
      slam::LocalizerStats st;
      std::vector<slam::LocalizedScan> run = localize(map, second, start, images, &st);
      size_t tracked = 0, tracked_right = 0, wrong = 0;
      for (const auto& r : run) {
        const auto g = trueAt(r.timestamp);
        if (r.state != slam::LocalizationState::Tracking) continue;
        ++tracked;
        tracked_right += g && close(r.pose, *g);
        wrong += r.relocalised && g && !close(r.pose, *g);
      }
      common::Json u = common::Json::object();
      u["scans"] = run.size();
      u["tracked"] = tracked;
      u["tracked_within_tolerance"] = tracked_right;
      u["relocalisations"] = st.relocalisations;
      u["image_relocalisations"] = st.image_relocalisations;
      u["wrong_fixes"] = wrong;
      uninterrupted[images ? "laser_camera" : "laser"] = std::move(u);
      if (!images) ref = std::move(run);
    }
    std::vector<io::StampedPose> tracked;  // ... where the truth agrees
    for (const auto& r : ref)
      if (const auto g = trueAt(r.timestamp); r.state == slam::LocalizationState::Tracking && g && close(r.pose, *g))
        tracked.push_back({r.timestamp, r.pose});
    evaluation::KidnapSchedule schedule;
    schedule.count = count;
    schedule.before_s = before, schedule.after_s = after, schedule.gap_s = gap, schedule.min_jump_m = min_jump;
    common::Json list = common::Json::array();
    struct Mode {
      const char* name;
      bool images;
      std::vector<double> found;
      int within_3s = 0, wrong_fixes = 0;
    };
    std::vector<Mode> modes = {{"laser", false, {}, 0, 0}, {"laser_camera", true, {}, 0, 0}};
    int jumps = 0;
    for (const evaluation::KidnapJump& jmp :
         evaluation::pickKidnapJumps(tracked, io::timestampOf(second.front()), io::timestampOf(second.back()), schedule)) {
      const io::StampedPose &s = tracked[jmp.from], &d = tracked[jmp.to];
      const double t1 = s.timestamp, t2 = d.timestamp;
      const std::vector<io::Measurement> stream = evaluation::spliceKidnapping(second, t1, t2, before, after);
      if (stream.empty()) continue;
      ++jumps;
      const slam::LocalizedScan* first = nullptr;
      for (const auto& r : ref)
        if (r.timestamp >= t1 - before) {
          first = &r;
          break;
        }
      common::Json jump = common::Json::object();
      jump["t1"] = t1;
      jump["t2"] = t2;
      jump["jump_m"] = std::hypot(d.pose.x - s.pose.x, d.pose.y - s.pose.y);
      for (Mode& mode : modes) {
        slam::LocalizerStats st;
        const std::vector<slam::LocalizedScan> run = localize(map, stream, first->pose, mode.images, &st);
        double reloc = std::numeric_limits<double>::infinity();
        int wrong = 0;
        for (const auto& r : run) {
          if (r.timestamp < t1 || r.state != slam::LocalizationState::Tracking) continue;
          const auto g = trueAt(r.timestamp + t2 - t1);
          if (!g) continue;
          const bool right = close(r.pose, *g);
          if (r.relocalised && !right) ++wrong;
          if (right && !std::isfinite(reloc)) reloc = r.timestamp - t1;
        }
        if (std::isfinite(reloc)) mode.found.push_back(reloc), mode.within_3s += reloc <= 3.0;
        mode.wrong_fixes += wrong;
        jump[std::string(mode.name) + "_s"] = std::isfinite(reloc) ? common::Json(reloc) : common::Json();
        jump[std::string(mode.name) + "_wrong_fixes"] = wrong;
        // Why: what the localizer did after the jump.
        jump[std::string(mode.name) + "_searches"] = st.place_searches;
        jump[std::string(mode.name) + "_discontinuities"] = st.discontinuities;
        jump[std::string(mode.name) + "_lost_events"] = st.lost_events;
        jump[std::string(mode.name) + "_image_searches"] = st.image_place_searches;
        jump[std::string(mode.name) + "_image_fixes"] = st.image_relocalisations;
      }
      std::cerr << jump.dump() << "\n";
      list.push(std::move(jump));
    }
    common::Json j = common::Json::object();
    j["city"] = city;
    j["map_keyframes"] = map.keyframes().size();
    size_t with_image = 0;
    for (const auto& k : map.keyframes()) with_image += k.has_image && !k.image_words.empty();
    j["map_keyframes_with_image_words"] = with_image;
    j["uninterrupted"] = std::move(uninterrupted);
    j["jumps"] = jumps;
    for (Mode& mode : modes) {
      common::Json m = common::Json::object();
      m["relocalised"] = mode.found.size();
      m["within_3s"] = mode.within_3s;
      m["relocalised_s_median"] = mode.found.empty() ? common::Json() : common::Json(common::percentile(mode.found, 50));
      m["wrong_fixes"] = mode.wrong_fixes;
      j[mode.name] = std::move(m);
    }
    j["list"] = std::move(list);
    std::cout << j.dump() << "\n";
  } catch (const common::InputError& e) {
    std::cerr << "city_kidnap: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
