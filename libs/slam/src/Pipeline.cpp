#include "urbanslam/slam/Pipeline.h"

#include <cmath>
#include <sstream>

#include "urbanslam/common/Timing.h"

namespace urbanslam::slam {

Pipeline::Pipeline(PipelineOptions options) : options_(std::move(options)) {
  std::stringstream ss(options_.input.laser_labels);
  std::string label;
  while (std::getline(ss, label, ',')) {
    label.erase(0, label.find_first_not_of(" \t"));
    label.erase(label.find_last_not_of(" \t") + 1);
    if (!label.empty()) labels_.push_back(label);
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::addObserver(PipelineObserver* observer) { observers_.push_back(observer); }

bool Pipeline::acceptLabel(const std::string& label) const {
  if (labels_.empty()) return true;
  for (const auto& l : labels_)
    if (l == label) return true;
  return false;
}

void Pipeline::applyRangeLimits(io::LaserScan& scan) const {
  const double lo = options_.input.min_range_m, hi = options_.input.max_range_m;
  if (lo <= 0 && hi <= 0) return;
  for (size_t i = 0; i < scan.ranges.size(); ++i)
    if (scan.ranges[i] < lo || (hi > 0 && scan.ranges[i] >= hi)) scan.valid[i] = 0;
}

bool Pipeline::step(io::DataSource& source) {
  // Processing time (reading included) accumulates here, so a paused GUI run reports the same
  // real-time factor as a batch run.
  common::Stopwatch sw;
  const bool more = stepOnce(source);
  stats_.wall_s += sw.seconds();
  return more;
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
    onOdometry(*od);
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    ++stats_.drive;
    onDrive(*dr);
  } else if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
    ++stats_.reference;
    reference_.push_back({ref->timestamp, ref->pose});
  } else if (const auto* img = std::get_if<io::CameraImage>(&m)) {
    ++stats_.images;
    for (auto* o : observers_) o->onImage(*img);
  } else if (std::holds_alternative<io::GpsFix>(m)) {
    ++stats_.gps;
  }
  return true;
}

void Pipeline::run(io::DataSource& source) {
  while (step(source)) {
  }
  finish();
}

void Pipeline::finish() {
  stats_.keyframes = keyframes_.size();
  for (auto* o : observers_) o->onFinished();
}

void Pipeline::onOdometry(const io::OdometryReading& m) {
  odom_ = m.pose;
  have_odom_ = true;
  odometry_trajectory_.push_back({m.timestamp, odom_});
}

// Dead reckoning of a car-like vehicle from speed and steering (kinematic bicycle model about
// the rear axle), integrated with the previous reading held over the interval.
void Pipeline::onDrive(const io::DriveReading& m) {
  if (have_drive_) {
    const double dt = m.timestamp - last_drive_.timestamp;
    if (dt > 0 && dt < 1.0) {
      const double v = last_drive_.speed_mps;
      const double w = v * std::tan(last_drive_.steering_rad) / options_.vehicle.wheelbase_m;
      odom_.x += v * dt * std::cos(odom_.phi);
      odom_.y += v * dt * std::sin(odom_.phi);
      odom_.phi = common::wrapToPi(odom_.phi + w * dt);
    }
  }
  last_drive_ = m;
  have_drive_ = true;
  have_odom_ = true;
  odometry_trajectory_.push_back({m.timestamp, odom_});
}

void Pipeline::onScan(io::LaserScan scan, double progress) {
  common::Stopwatch sw;
  if (!acceptLabel(scan.label)) return;
  ++stats_.scans_used;
  applyRangeLimits(scan);
  // Dead reckoning: the scan sits at the latest odometry pose (the origin before any odometry).
  const common::Pose2 pose = have_odom_ ? odom_ : common::Pose2{};
  bool make_keyframe = keyframes_.empty();
  if (!make_keyframe) {
    const common::Pose2 d = common::between(keyframes_.back().pose, pose);
    make_keyframe = std::hypot(d.x, d.y) >= options_.keyframes.min_translation_m ||
                    std::abs(d.phi) >= options_.keyframes.min_rotation_deg * M_PI / 180.0;
  }
  if (make_keyframe) {
    Keyframe kf{keyframes_.size(), scan.timestamp, pose, std::move(scan)};
    keyframes_.push_back(std::move(kf));
    const Keyframe& k = keyframes_.back();
    for (auto* o : observers_) o->onKeyframe({k.index, k.timestamp, k.pose, {}, &k.scan});
  }
  const double ms = sw.milliseconds();
  stats_.step_ms.push_back(ms);
  StepEvent ev{stats_.scans_used, keyframes_.size(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

std::vector<io::PosedScan> Pipeline::posedKeyframes() const {
  std::vector<io::PosedScan> out;
  out.reserve(keyframes_.size());
  for (const auto& k : keyframes_) out.push_back({k.pose, &k.scan});
  return out;
}

}  // namespace urbanslam::slam
