#include "urbanslam/slam/Pipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/Recovery.h"
#include "urbanslam/slam/CameraMotion.h"
#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::slam {

namespace {

// A filter failure in a job global SLAM took from local SLAM, with the measurement that made
// the job: the error names it however late global SLAM got to the job.
struct FilterFailureAt : std::runtime_error {
  FilterFailureAt(const std::string& what, size_t measurement, double timestamp)
      : std::runtime_error(what), measurement(measurement), timestamp(timestamp) {}
  size_t measurement;
  double timestamp;
};

// The filter behind the map (none in dead reckoning).
std::unique_ptr<esdf::Esdf> makeFilter(const PipelineOptions& options) {
  if (options.estimator.type != EstimatorOptions::Type::Esdf) return nullptr;
  esdf::EsdfOptions eo;
  eo.relinearise = options.estimator.relinearise;
  eo.chi2_gate_probability = options.loop_closure.chi2_gate_probability;
  eo.gate_covariance = esdf::CovarianceMode::Exact;
  return std::make_unique<esdf::Esdf>(eo);
}

}  // namespace

Pipeline::Pipeline(PipelineOptions options)
    : options_(std::move(options)),
      input_(options_.input),
      reference_("reference poses", options_.map.scan_spill_dir),
      map_(makeFilter(options_), std::max(1.0, options_.loop_closure.search_radius_m),
           static_cast<size_t>(options_.map.scan_cache_mb * 1024 * 1024), options_.map.scan_spill_dir,
           options_.estimator.reduced_pose_graph, static_cast<size_t>(options_.estimator.reduced_after_keyframes)),
      local_(options_),
      global_(options_, map_, stats_, observers_),
      images_(options_.loop_closure.image_max_offset_s),
      global_worker_(options_.estimator.global_thread) {}

Pipeline::~Pipeline() = default;

void PipelineStats::recordStep(double ms, size_t keyframes) {
  step_ms.add(ms);
  size_t decade = 0;
  for (size_t n = keyframes; n >= 10; n /= 10) ++decade;
  if (step_ms_by_decade.size() <= decade) step_ms_by_decade.resize(decade + 1);
  step_ms_by_decade[decade].add(ms);
}

void Pipeline::addObserver(PipelineObserver* observer) { observers_.push_back(observer); }

template <typename Body>
void Pipeline::reportingFilterFailures(const io::DataSource& source, const std::string& where, Body&& body) {
  // Values that are each in range can still be too extreme together for the filter's
  // arithmetic (an odometry jump of thousands of km): that is the log's fault, not a bug.
  const std::string hint = " (a pose, odometry or range far out of line with the rest of the log?)";
  try {
    body();
  } catch (const FilterFailureAt& e) {
    std::ostringstream at;
    at.precision(15);
    at << source.path() << ": measurement " << e.measurement << " (t = " << e.timestamp << " s): the filter's " << e.what() << " after it";
    throw common::InputError(at.str() + hint);
  } catch (const esdf::NotPositiveDefinite& e) {
    throw common::InputError(source.path() + ": " + where + ": the filter's " + e.what() + hint);
  }
}

size_t Pipeline::postToGlobalSlam(std::function<void()> body) {
  return global_worker_.post([body = std::move(body), measurement = stats_.measurements, t = stats_.last_timestamp]() mutable {
    try {
      body();
    } catch (const esdf::NotPositiveDefinite& e) {
      throw FilterFailureAt(e.what(), measurement, t);
    }
  });
}

bool Pipeline::step(io::DataSource& source) {
  // Processing time (reading included) accumulates here, so a paused GUI run reports the same
  // real-time factor as a batch run.
  common::Stopwatch sw;
  bool more = false;
  reportingFilterFailures(source, "measurement " + std::to_string(stats_.measurements + 1), [&] { more = stepOnce(source); });
  stats_.wall_s += sw.seconds();
  return more;
}

void Pipeline::writeState(common::BinaryWriter& w) const {
  global_worker_.drain();  // the state global SLAM is working towards
  writeStateNow(w);
}

void Pipeline::waitForGlobalSlam(const io::DataSource& source) {
  common::Stopwatch sw;
  reportingFilterFailures(source, "up to measurement " + std::to_string(stats_.measurements), [&] { drainGlobalSlam(); });
  stats_.wall_s += sw.seconds();
}

void Pipeline::drainGlobalSlam() {
  global_worker_.drain();
  stats_.global_backlog_max = std::max(stats_.global_backlog_max, global_worker_.maxBacklog());
}

bool Pipeline::stepOnce(io::DataSource& source) {
  io::Measurement m;
  if (!source.next(m)) return false;
  ++stats_.measurements;
  const double t = io::timestampOf(m);
  if (!have_first_ts_) {
    stats_.first_timestamp = t;
    have_first_ts_ = true;
  }
  stats_.last_timestamp = t;
  if (auto* scan = std::get_if<io::LaserScan>(&m)) {
    ++stats_.scans;
    onScan(std::move(*scan), source.progress());
  } else if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
    ++stats_.odometry;
    if (local_.addOdometry(*od)) map_.addOdometry(od->timestamp, local_.motion().odometryPose());
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    ++stats_.drive;
    if (local_.addDrive(*dr)) map_.addOdometry(dr->timestamp, local_.motion().odometryPose());
  } else if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
    ++stats_.reference;
    reference_.push_back({ref->timestamp, ref->pose});
  } else if (const auto* img = std::get_if<io::CameraImage>(&m)) {
    ++stats_.images;
    for (auto* o : observers_) o->onImage(*img);
    onCameraImage(*img, source.progress());
  } else if (std::holds_alternative<io::GpsFix>(m)) {
    ++stats_.gps;
  }
  return true;
}

void Pipeline::run(io::DataSource& source) {
  runInput(source);
  finish(source);
}

void Pipeline::runInput(io::DataSource& source) {
  while (step(source)) {
  }
  waitForGlobalSlam(source);
}

void Pipeline::finish(const io::DataSource& source) {
  reportingFilterFailures(source, "at the end of the log", [&] { finish(); });
}

void Pipeline::finish() {
  finished_ = true;
  common::Stopwatch sw;
  if (auto last = images_.finish()) postImage(std::move(*last));  // the last keyframe's image is final now
  global_worker_.post([this] { global_.finish(); });
  drainGlobalSlam();
  stats_.wall_s += sw.seconds();
  stats_.keyframes = map_.size();
  for (auto* o : observers_) o->onFinished();
}

void Pipeline::onScan(io::LaserScan scan, double progress) {
  common::Stopwatch sw;
  if (!input_.accepts(scan.label)) return;
  ++stats_.scans_used;
  input_.limitRanges(scan);
  // Local SLAM's own time: waiting for global SLAM's submap estimate is counted apart
  // (timing.global_wait_s), or a batch run, which always catches up with global SLAM, would
  // report global SLAM's time as the front end's.
  const double waited_before_s = stats_.global_wait_s;
  const auto waitedMs = [&] { return (stats_.global_wait_s - waited_before_s) * 1e3; };
  if (local_.isKeyframe()) {
    common::Stopwatch kw;
    addKeyframe(std::move(scan));
    stats_.keyframe_ms.add(kw.milliseconds() - waitedMs());
  } else if (const auto anchor = local_.placeScan(scan, map_.lastAnchor())) {
    ++stats_.scans_anchored;
    map_.addAnchor(*anchor);
  }
  const double ms = sw.milliseconds() - waitedMs();
  stats_.recordStep(ms, local_.keyframes());
  StepEvent ev{stats_.scans_used, local_.keyframes(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

void Pipeline::addKeyframe(io::LaserScan scan, const std::optional<CameraMeasurement>& camera_motion) {
  const size_t k = local_.keyframes();
  // 1. The previous keyframe's image is final once this keyframe exists (it may be nearer in time).
  if (auto done = images_.keyframeAdded(k, scan.timestamp)) postImage(std::move(*done));
  // 2. Local SLAM: the motion since the previous keyframe, refined by the submap match (the
  //    submap as global SLAM saw it a few keyframes ago).
  correctSubmap(k);
  KeyframeConstraint c = local_.keyframeConstraint(scan);
  if (c.match == KeyframeConstraint::Match::Used) ++stats_.scan_matches_used;
  if (c.match == KeyframeConstraint::Match::Rejected) ++stats_.scan_matches_rejected;
  //    Without scans, the camera's view of the motion refines it instead.
  if (camera_motion && k > 0) {
    const CameraMotionResult r = fuseCameraMotion(c, *camera_motion, 1.0 - options_.local.odometry_outlier_probability);
    c = r.constraint;
    ++(r.used ? stats_.camera_motions_used : stats_.camera_motions_rejected);
  }
  // 3. The keyframe anchors the trajectory at sensor times and joins the local submap.
  const double timestamp = scan.timestamp;
  // From here on the scan is the one the map keeps (ranges to the millimetre), as a map read
  // back from its file has it: a continued run rebuilds the submap from those.
  io::CompactScan kept(scan);
  kept.expandInto(scan);
  map_.addAnchor({timestamp, k, common::Pose2{}, local_.motion().odometryPose()});
  local_.keyframeAdded(scan, c.z);
  // 4. Global SLAM, in order: the keyframe into the filter as a delayed pose, then loop closures
  //    against earlier keyframes of the keyframe a few before it (GlobalSlam::searchLag: its
  //    scan judged by the keyframes on both sides).
  // The observers get the keyframe's scan as the map keeps it: the expanded copy local SLAM used
  // goes along rather than being expanded again there.
  //    Then the submap's keyframes as global SLAM sees them, for local SLAM to take later.
  const size_t ticket = postToGlobalSlam([this, kf = Keyframe{k, timestamp, {}, false, false, {}}, kept = std::move(kept), c,
                                          scan = std::move(scan), handed_over = std::chrono::steady_clock::now()]() mutable {
    const std::array<double, 9> cov = global_.addKeyframe(std::move(kf), std::move(kept), c);
    const Keyframe& added = map_.back();
    for (auto* o : observers_) o->onKeyframe({added.index, added.timestamp, added.pose, cov, &scan});
    // The camera's views are kept for this keyframe's candidates only: a continued run (which
    // starts between keyframes without them) then decides as the whole run did.
    camera_views_.clear();
    global_.closeLoops(added.index, handed_over);
    if (takesSubmapCorrections()) {
      SubmapEstimate e{added.index, {}};
      const size_t n = std::min(map_.size(), static_cast<size_t>(options_.local.submap_keyframes));
      for (size_t i = map_.size() - n; i < map_.size(); ++i) e.poses.push_back(map_.keyframes()[i].pose);
      submap_corrections_.publish(std::move(e));
    }
  });
  if (takesSubmapCorrections()) {
    keyframe_tickets_.emplace_back(k, ticket);
    while (keyframe_tickets_.size() > static_cast<size_t>(options_.local.correction_lag_keyframes) + 1) keyframe_tickets_.pop_front();
  }
}

void Pipeline::correctSubmap(size_t k) {
  const size_t lag = static_cast<size_t>(options_.local.correction_lag_keyframes);
  if (!takesSubmapCorrections() || k < lag) return;
  const size_t j = k - lag;
  std::optional<SubmapEstimate> e = submap_corrections_.take(j);
  if (!e) {
    // Global SLAM is more than the lag behind (a continued run has every estimate it needs).
    const auto job = std::find_if(keyframe_tickets_.begin(), keyframe_tickets_.end(), [&](const auto& t) { return t.first == j; });
    if (job == keyframe_tickets_.end()) return;
    common::Stopwatch sw;
    global_worker_.waitFor(job->second);
    stats_.global_wait_s += sw.seconds();
    e = submap_corrections_.take(j);
  }
  if (e) local_.correctSubmap(*e);
}

}  // namespace urbanslam::slam
