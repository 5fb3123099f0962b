// What a run leaves for another to continue: every member of the pipeline and its parts that a
// later step reads, written raw (doubles as their bits), so that a pipeline read back continues
// exactly as the one written would have. Left out is only what the options (the reader is built
// with the same ones) or the written state rebuild identically: the labels, the submap's beams
// and prepared reference, the laser detector's keyframe features.
//
// The layout, section by section, is documented in libs/slam/README.md ("The map file"); a change
// here is a change of the format version (MapFile.h).
#include <algorithm>
#include <limits>
#include <string>

#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/laser_loop/LoopDetector.h"
#include "urbanslam/slam/KeyframeNodes.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::slam {

namespace {

using common::BinaryReader;
using common::BinaryWriter;

constexpr size_t kNone = std::numeric_limits<size_t>::max();

void writePose(BinaryWriter& w, const common::Pose2& p) {
  w.f64(p.x);
  w.f64(p.y);
  w.f64(p.phi);
}

common::Pose2 readPose(BinaryReader& r) {
  common::Pose2 p;
  p.x = r.f64();
  p.y = r.f64();
  p.phi = r.f64();
  return p;
}

void writeScan(BinaryWriter& w, const io::LaserScan& s) {
  w.f64(s.timestamp);
  w.string(s.label);
  w.size(s.ranges.size());
  for (float v : s.ranges) w.f32(v);
  w.size(s.valid.size());
  w.raw(s.valid.data(), s.valid.size());
  w.f64(s.angle_min_rad);
  w.f64(s.angle_increment_rad);
  w.f64(s.max_range_m);
  writePose(w, s.sensor_pose);
}

io::LaserScan readScan(BinaryReader& r) {
  io::LaserScan s;
  s.timestamp = r.f64();
  s.label = r.string();
  s.ranges.resize(r.count(4));
  for (float& v : s.ranges) v = r.f32();
  s.valid.resize(r.count(1));
  r.raw(s.valid.data(), s.valid.size());
  if (s.valid.size() != s.ranges.size())
    r.fail("a scan of " + std::to_string(s.ranges.size()) + " ranges and " + std::to_string(s.valid.size()) + " validity flags");
  s.angle_min_rad = r.f64();
  s.angle_increment_rad = r.f64();
  s.max_range_m = r.f64();
  s.sensor_pose = readPose(r);
  return s;
}

void writeImage(BinaryWriter& w, const io::CameraImage& im) {
  w.f64(im.timestamp);
  w.string(im.label);
  w.string(im.source);
  w.i32(im.width);
  w.i32(im.height);
  w.boolean(im.pixels != nullptr);
  if (im.pixels) {
    w.size(im.pixels->size());
    w.raw(im.pixels->data(), im.pixels->size());
  }
}

io::CameraImage readImage(BinaryReader& r) {
  io::CameraImage im;
  im.timestamp = r.f64();
  im.label = r.string();
  im.source = r.string();
  im.width = r.i32();
  im.height = r.i32();
  if (r.boolean()) {
    auto pixels = std::make_shared<std::vector<uint8_t>>(r.count(1));
    r.raw(pixels->data(), pixels->size());
    // The pipeline reads width x height pixels from the buffer.
    if (im.width < 0 || im.height < 0 ||
        pixels->size() / (im.width > 0 ? static_cast<size_t>(im.width) : 1) < static_cast<size_t>(im.height))
      r.fail("an image of " + std::to_string(im.width) + " x " + std::to_string(im.height) + " pixels in " +
             std::to_string(pixels->size()) + " bytes");
    im.pixels = std::move(pixels);
  }
  return im;
}

void writeOptionalImage(BinaryWriter& w, const std::optional<io::CameraImage>& im) {
  w.boolean(im.has_value());
  if (im) writeImage(w, *im);
}

std::optional<io::CameraImage> readOptionalImage(BinaryReader& r) {
  if (!r.boolean()) return std::nullopt;
  return readImage(r);
}

std::vector<double> readDoubles(BinaryReader& r) {
  std::vector<double> v(r.count(8));
  for (double& x : v) x = r.f64();
  return v;
}

void writeRecord(BinaryWriter& w, const LoopClosureRecord& c) {
  w.size(c.from);
  w.size(c.to);
  w.f64(c.from_time);
  w.f64(c.to_time);
  w.string(proposerName(c.detector));
  w.f64(c.score);
  w.boolean(c.accepted);
  w.u8(static_cast<std::uint8_t>(c.reason));
  writePose(w, c.measurement);
  w.matrix(Eigen::Matrix3d(c.information));
  w.f64(c.rms_m);
  w.f64(c.mahalanobis2);
  w.f64(c.gate_threshold);
  w.f64(c.free_space_conflict);
  w.f64(c.prior_sigma_m);
  w.boolean(c.bearing_only);
  w.u8(static_cast<std::uint8_t>(c.confirmed_by));
  w.boolean(c.restarts_skipped);
}

LoopClosureRecord readRecord(BinaryReader& r, size_t keyframes, std::uint32_t format_version) {
  LoopClosureRecord c;
  c.from = r.size();
  c.to = r.size();
  if (c.from >= keyframes || c.to >= keyframes)
    r.fail("loop closure " + std::to_string(c.from) + " -> " + std::to_string(c.to) + " among " + std::to_string(keyframes) + " keyframes");
  c.from_time = r.f64();
  c.to_time = r.f64();
  const std::string detector = r.string();
  const std::optional<Proposer> proposer = parseProposer(detector);
  if (!proposer) r.fail("loop closure detector '" + detector + "'");
  c.detector = *proposer;
  c.score = r.f64();
  c.accepted = r.boolean();
  const std::uint8_t reason = r.u8();
  if (reason > static_cast<std::uint8_t>(ClosureReason::Join)) r.fail("loop closure reason " + std::to_string(reason));
  c.reason = static_cast<ClosureReason>(reason);
  c.measurement = readPose(r);
  c.information = r.matrix<3, 3>();
  c.rms_m = r.f64();
  c.mahalanobis2 = r.f64();
  c.gate_threshold = r.f64();
  c.free_space_conflict = r.f64();
  c.prior_sigma_m = r.f64();
  // Before version 6 every camera closure measured bearing and heading only: those are the image
  // detections that no scan alignment measured (no alignment residual).
  c.bearing_only = format_version >= 6 ? r.boolean()
                                       : c.detector == Proposer::Image && c.rms_m == 0 && c.reason != ClosureReason::CameraGeometry &&
                                             c.reason != ClosureReason::NoScans;
  // Before version 7 what confirmed a closure was not kept.
  if (format_version >= 7) {
    const std::uint8_t confirmed = r.u8();
    if (confirmed > static_cast<std::uint8_t>(Confirmation::Jointly)) r.fail("loop closure confirmation " + std::to_string(confirmed));
    c.confirmed_by = static_cast<Confirmation>(confirmed);
  }
  // Before version 12 no closure left the ambiguity restarts out.
  if (format_version >= 12) c.restarts_skipped = r.boolean();
  return c;
}

void writeStats(BinaryWriter& w, const PipelineStats& s) {
  for (size_t v : {s.measurements,
                   s.scans,
                   s.scans_used,
                   s.odometry,
                   s.drive,
                   s.images,
                   s.gps,
                   s.reference,
                   s.keyframes,
                   s.scan_matches_used,
                   s.scan_matches_rejected,
                   s.scans_anchored,
                   s.closures_tried,
                   s.closures_accepted,
                   s.closures_rejected,
                   s.image_keyframes,
                   s.image_proposals,
                   s.camera_motions_used,
                   s.camera_motions_rejected,
                   s.global_backlog_max})
    w.size(v);
  w.f64(s.first_timestamp);
  w.f64(s.last_timestamp);
  w.f64(s.wall_s);
  w.f64(s.global_wait_s);
  s.step_ms.write(w);
  w.size(s.step_ms_by_decade.size());
  for (const auto& d : s.step_ms_by_decade) d.write(w);
  s.keyframe_ms.write(w);
  s.closure_ms.write(w);
  s.global_latency_ms.write(w);
}

// Format 8 keeps the durations as histograms; earlier formats kept every one.
common::DurationHistogram readDurations(BinaryReader& r, std::uint32_t format_version) {
  common::DurationHistogram h;
  if (format_version >= 8) {
    h.read(r);
  } else {
    for (double ms : readDoubles(r)) h.add(ms);
  }
  return h;
}

void readStats(BinaryReader& r, PipelineStats& s, std::uint32_t format_version) {
  for (size_t* v : {&s.measurements,
                    &s.scans,
                    &s.scans_used,
                    &s.odometry,
                    &s.drive,
                    &s.images,
                    &s.gps,
                    &s.reference,
                    &s.keyframes,
                    &s.scan_matches_used,
                    &s.scan_matches_rejected,
                    &s.scans_anchored,
                    &s.closures_tried,
                    &s.closures_accepted,
                    &s.closures_rejected,
                    &s.image_keyframes,
                    &s.image_proposals,
                    &s.camera_motions_used,
                    &s.camera_motions_rejected,
                    &s.global_backlog_max})
    *v = r.size();
  s.first_timestamp = r.f64();
  s.last_timestamp = r.f64();
  s.wall_s = r.f64();
  s.global_wait_s = r.f64();
  s.step_ms = readDurations(r, format_version);
  s.step_ms_by_decade.resize(r.count(8));
  for (auto& d : s.step_ms_by_decade) d = readDurations(r, format_version);
  s.keyframe_ms = readDurations(r, format_version);
  s.closure_ms = readDurations(r, format_version);
  s.global_latency_ms = readDurations(r, format_version);
}

void writePointSet(BinaryWriter& w, const alignment::PointSet& points) {
  w.size(points.size());
  for (const auto& p : points) {
    w.matrix(Eigen::Vector2d(p.p));
    w.matrix(Eigen::Matrix2d(p.cov));
    w.f64(p.range_m);
    w.f64(p.bearing_rad);
    w.i32(p.beam);
    w.matrix(Eigen::Vector2d(p.origin));
  }
}

// Before version 13 a point set held no sensor positions: they are then the set's origin.
alignment::PointSet readPointSet(BinaryReader& r, bool with_origins) {
  alignment::PointSet points(r.count((2 + 4 + 2) * 8 + 4 + (with_origins ? 2 * 8 : 0)));
  for (auto& p : points) {
    p.p = r.matrix<2, 1>();
    p.cov = r.matrix<2, 2>();
    p.range_m = r.f64();
    p.bearing_rad = r.f64();
    p.beam = r.i32();
    if (with_origins) p.origin = r.matrix<2, 1>();
  }
  return points;
}

// Sections of the payload, in file order.
constexpr std::uint32_t kStatsTag = common::sectionTag("STAT");
constexpr std::uint32_t kMapTag = common::sectionTag("MAP ");
constexpr std::uint32_t kFilterTag = common::sectionTag("ESDF");
constexpr std::uint32_t kLocalTag = common::sectionTag("LOCL");
constexpr std::uint32_t kGlobalTag = common::sectionTag("GLOB");
constexpr std::uint32_t kImagesTag = common::sectionTag("IMGS");

}  // namespace

void LoopClosureRecordCodec::write(BinaryWriter& w, const LoopClosureRecord& c) { writeRecord(w, c); }

LoopClosureRecord LoopClosureRecordCodec::read(BinaryReader& r) {
  return readRecord(r, std::numeric_limits<size_t>::max(), kMapFormatVersion);
}

void Pipeline::StampedPoseCodec::write(BinaryWriter& w, const io::StampedPose& p) {
  w.f64(p.timestamp);
  writePose(w, p.pose);
}

io::StampedPose Pipeline::StampedPoseCodec::read(BinaryReader& r) {
  io::StampedPose p;
  p.timestamp = r.f64();
  p.pose = readPose(r);
  return p;
}

void GraphEdgeCodec::write(BinaryWriter& w, const GraphEdge& e) {
  w.size(e.from);
  w.size(e.to);
  writePose(w, e.measurement);
  w.matrix(Eigen::Matrix3d(e.information));
  w.boolean(e.loop_closure);
}

GraphEdge GraphEdgeCodec::read(BinaryReader& r) {
  GraphEdge e;
  e.from = r.size();
  e.to = r.size();
  e.measurement = readPose(r);
  e.information = r.matrix<3, 3>();
  e.loop_closure = r.boolean();
  return e;
}

// --- Map ---

void KeyframeGrid::writeState(BinaryWriter& w) const {
  // In key order, so that the same grid always gives the same bytes.
  std::vector<uint64_t> keys;
  keys.reserve(cells_.size());
  for (const auto& [k, v] : cells_) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  w.size(keys.size());
  for (uint64_t k : keys) {
    w.u64(k);
    const auto& v = cells_.at(k);
    w.size(v.size());
    for (size_t i : v) w.size(i);
  }
}

void KeyframeGrid::readState(BinaryReader& r, size_t keyframes) {
  cells_.clear();
  const size_t n = r.count(16);
  for (size_t c = 0; c < n; ++c) {
    std::vector<size_t>& v = cells_[r.u64()];
    v.resize(r.count(8));
    for (size_t& i : v) {
      i = r.size();
      if (i >= keyframes) r.fail("spatial index entry " + std::to_string(i) + " among " + std::to_string(keyframes) + " keyframes");
    }
  }
}

void Map::writeState(BinaryWriter& w) const {
  w.size(keyframes_.size());
  io::LaserScan scan;
  for (const Keyframe& k : keyframes_) {
    w.size(k.index);
    w.f64(k.timestamp);
    writePose(w, k.pose);
    scans_.expandInto(k.index, scan);
    writeScan(w, scan);
    w.boolean(k.has_image);
    w.size(k.image_words.entries.size());
    for (const auto& e : k.image_words.entries) {
      w.u32(e.word);
      w.f32(e.weight);
    }
  }
  w.size(edges_.size());
  edges_.forEach([&](const GraphEdge& e) { GraphEdgeCodec::write(w, e); });
  index_.writeState(w);
  w.size(anchors_.size());
  for (const ScanAnchor& a : anchors_) {
    w.f64(a.timestamp);
    w.size(a.keyframe);
    writePose(w, a.offset);
    writePose(w, a.odom);
  }
  w.size(odometry_.size());
  odometry_.forEach([&](const OdometrySample& s) { OdometryCodec::write(w, s); });
}

void Map::OdometryCodec::write(BinaryWriter& w, const OdometrySample& s) {
  w.f64(s.timestamp);
  writePose(w, s.odom);
  w.u64(s.anchor == kNone ? ~std::uint64_t{0} : static_cast<std::uint64_t>(s.anchor));
}

Map::OdometrySample Map::OdometryCodec::read(BinaryReader& r) {
  OdometrySample s;
  s.timestamp = r.f64();
  s.odom = readPose(r);
  const std::uint64_t a = r.u64();
  s.anchor = a == ~std::uint64_t{0} ? kNone : static_cast<size_t>(a);
  return s;
}

void Map::readState(BinaryReader& r) {
  keyframes_.resize(r.count(8 + 8 + 24 + 1));
  scans_.clear();
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    Keyframe& k = keyframes_[i];
    k.index = r.size();
    if (k.index != i) r.fail("keyframe " + std::to_string(i) + " numbered " + std::to_string(k.index));
    k.timestamp = r.f64();
    k.pose = readPose(r);
    io::CompactScan scan(readScan(r));
    k.has_scan = !scan.empty();
    scans_.add(std::move(scan));
    k.has_image = r.boolean();
    k.image_words.entries.resize(r.count(8));
    for (auto& e : k.image_words.entries) {
      e.word = r.u32();
      e.weight = r.f32();
    }
  }
  const size_t n = keyframes_.size();
  edges_.clear();
  for (size_t i = 0, count = r.count(8 + 8 + 24 + 72 + 1); i < count; ++i) {
    const GraphEdge e = GraphEdgeCodec::read(r);
    if (e.from >= n || e.to >= n) r.fail("graph edge " + std::to_string(e.from) + " -> " + std::to_string(e.to));
    edges_.push_back(e);
  }
  index_.readState(r, n);
  anchors_.resize(r.count(8 + 8 + 48));
  for (ScanAnchor& a : anchors_) {
    a.timestamp = r.f64();
    a.keyframe = r.size();
    if (a.keyframe >= n) r.fail("scan anchored to keyframe " + std::to_string(a.keyframe));
    a.offset = readPose(r);
    a.odom = readPose(r);
  }
  odometry_.clear();
  for (size_t i = 0, count = r.count(8 + 24 + 8); i < count; ++i) {
    const OdometrySample s = OdometryCodec::read(r);
    if (s.anchor != kNone && s.anchor >= anchors_.size()) r.fail("odometry sample after anchor " + std::to_string(s.anchor));
    odometry_.push_back(s);
  }
}

// --- Local SLAM ---

void MotionIntegrator::writeState(BinaryWriter& w) const {
  writePose(w, increment_);
  writePose(w, odom_);
  w.matrix(Eigen::Matrix3d(cov_));
  w.matrix(Eigen::Matrix3d(odometry_sqrt_));
  w.boolean(have_input_);
  w.boolean(have_odom_);
  w.boolean(have_drive_);
  w.f64(last_odom_.timestamp);
  writePose(w, last_odom_.pose);
  w.f64(last_drive_.timestamp);
  w.f64(last_drive_.speed_mps);
  w.f64(last_drive_.steering_rad);
}

void MotionIntegrator::readState(BinaryReader& r) {
  increment_ = readPose(r);
  odom_ = readPose(r);
  cov_ = r.matrix<3, 3>();
  odometry_sqrt_ = r.matrix<3, 3>();
  have_input_ = r.boolean();
  have_odom_ = r.boolean();
  have_drive_ = r.boolean();
  last_odom_.timestamp = r.f64();
  last_odom_.pose = readPose(r);
  last_drive_.timestamp = r.f64();
  last_drive_.speed_mps = r.f64();
  last_drive_.steering_rad = r.f64();
}

void LocalSubmap::writeState(BinaryWriter& w) const {
  w.size(sets_.size());
  for (const auto& s : sets_) writePointSet(w, s);
  w.size(generation_);
  w.f64(seen_through_.seenCount());
  w.f64(seen_through_.pointCount());
  w.f64(seen_through_displaced_.seenCount());
  w.f64(seen_through_displaced_.pointCount());
  w.f64(heading_corrections_.sumSquares());
  w.f64(heading_corrections_.sumMatched());
  w.f64(heading_corrections_.matches());
  w.f64(outvotes_.outvotes());
  w.f64(outvotes_.matches());
}

void LocalSubmap::readState(BinaryReader& r, bool with_heading_corrections, bool with_origins, bool with_outvotes) {
  const size_t n = r.count(8);
  if (n > capacity_) r.fail("a local submap of " + std::to_string(n) + " keyframes where it holds " + std::to_string(capacity_));
  sets_.clear();
  beams_.clear();
  for (size_t i = 0; i < n; ++i) {
    sets_.push_back(readPointSet(r, with_origins));
    beams_.emplace_back(sets_.back(), matcher_.free_margin_m, matcher_.free_margin_fraction);
  }
  generation_ = r.size();
  cache_ = Cache{};
  const double seen = r.f64(), points = r.f64();
  seen_through_.restore(seen, points);
  const double seen_d = r.f64(), points_d = r.f64();
  seen_through_displaced_.restore(seen_d, points_d);
  outvotes_ = alignment::OdometryOutvotes{};
  if (!with_heading_corrections) return;  // an older map: the next matches learn them again
  const double sum_squares = r.f64(), sum_matched = r.f64(), matches = r.f64();
  if (!(sum_squares >= 0) || !(sum_matched >= 0) || !(matches >= 0)) r.fail("local SLAM's heading corrections");
  heading_corrections_.restore(sum_squares, sum_matched, matches);
  if (!with_outvotes) return;  // an older map: the next matches learn it again
  const double outvotes = r.f64(), outvote_matches = r.f64();
  if (!(outvotes >= 0) || !(outvote_matches >= outvotes)) r.fail("local SLAM's odometry outvotes");
  outvotes_.restore(outvotes, outvote_matches);
}

void LocalSlam::writeState(BinaryWriter& w) const {
  motion_.writeState(w);
  submap_.writeState(w);
  w.boolean(have_scan_keyframe_);
  w.size(local_poses_.size());
  for (const auto& p : local_poses_) writePose(w, p);
  w.size(keyframes_);
  w.boolean(last_keyframe_has_scan_);
  w.boolean(have_anchor_);
  w.f64(last_anchor_time_);
}

void LocalSlam::readState(BinaryReader& r, bool with_heading_corrections, bool with_origins, bool with_outvotes) {
  motion_.readState(r);
  submap_.readState(r, with_heading_corrections, with_origins, with_outvotes);
  have_scan_keyframe_ = r.boolean();
  local_poses_.resize(r.count(24));
  for (auto& p : local_poses_) p = readPose(r);
  if (local_poses_.size() != submap_.size()) r.fail("local submap poses");
  keyframes_ = r.size();
  last_keyframe_has_scan_ = r.boolean();
  have_anchor_ = r.boolean();
  last_anchor_time_ = r.f64();
}

void SubmapCorrections::writeState(BinaryWriter& w) const {
  std::lock_guard<std::mutex> lock(mutex_);
  w.size(published_.size());
  for (const auto& e : published_) {
    w.size(e.keyframe);
    w.size(e.poses.size());
    for (const auto& p : e.poses) writePose(w, p);
  }
}

void SubmapCorrections::readState(BinaryReader& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  published_.resize(r.count(16));
  for (auto& e : published_) {
    e.keyframe = r.size();
    e.poses.resize(r.count(24));
    for (auto& p : e.poses) p = readPose(r);
    if (e.poses.size() > e.keyframe + 1) r.fail("submap estimate of keyframe " + std::to_string(e.keyframe));
  }
}

// --- Global SLAM ---

void LoopCloser::writeState(BinaryWriter& w) const {
  w.u64(cached_for_ == static_cast<size_t>(-1) ? ~std::uint64_t{0} : static_cast<std::uint64_t>(cached_for_));
  std::vector<size_t> keys;
  for (const auto& [k, v] : cached_) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  w.size(keys.size());
  for (size_t k : keys) {
    w.size(k);
    w.matrix(Eigen::Matrix3d(cached_.at(k)));
  }
}

void LoopCloser::readState(BinaryReader& r) {
  const std::uint64_t f = r.u64();
  cached_for_ = f == ~std::uint64_t{0} ? static_cast<size_t>(-1) : static_cast<size_t>(f);
  cached_.clear();
  const size_t n = r.count(8 + 72);
  for (size_t i = 0; i < n; ++i) {
    const size_t k = r.size();
    cached_[k] = r.matrix<3, 3>();
  }
}

void GlobalSlam::writeState(BinaryWriter& w) const {
  closer_.writeState(w);
  w.size(pending_.size());
  for (const auto& c : pending_) writeRecord(w, c);
  w.size(closures_.size());
  closures_.forEach([&](const LoopClosureRecord& c) { writeRecord(w, c); });
  w.boolean(dirty_since_recovery_);
  w.size(last_full_size_);
  w.size(next_search_);
  w.size(waiting_.size());
  for (size_t k : waiting_) w.size(k);
}

void GlobalSlam::readState(BinaryReader& r, std::uint32_t format_version) {
  closer_.readState(r);
  const size_t n = map_.size();
  constexpr size_t kRecordBytes = 2 * 8 + 2 * 8 + 8 + 8 + 2 + 24 + 72 + 5 * 8;
  pending_.clear();
  for (size_t i = 0, count = r.count(kRecordBytes); i < count; ++i) pending_.push_back(readRecord(r, n, format_version));
  closures_.clear();
  last_accepted_.reset();
  for (size_t i = 0, count = r.count(kRecordBytes); i < count; ++i) {
    const LoopClosureRecord c = readRecord(r, n, format_version);
    keepIfNewestAccepted(c);
    closures_.push_back(c);
  }
  dirty_since_recovery_ = r.boolean();
  last_full_size_ = r.size();
  waiting_.clear();
  if (format_version >= 14) {
    next_search_ = r.size();
    for (size_t i = 0, count = r.count(8); i < count; ++i) waiting_.push_back(r.size());
    if (next_search_ > n || std::any_of(waiting_.begin(), waiting_.end(), [&](size_t k) { return k < next_search_ || k >= n; }))
      throw common::InputError("global SLAM's keyframes awaiting their loop search are not in the map");
  } else {
    // No cursor before version 14: every build that wrote one searched each keyframe's loop
    // closures when it was added, so every keyframe is taken as searched (searching one again
    // could add a closure on a pair already closed, its information counted twice).
    next_search_ = n;
  }
  // The classifier's keyframe features are not saved: a function of each keyframe's scan,
  // computed when first needed (laserDetector()).
}

// --- Camera images ---

void KeyframeImageAssigner::writeState(BinaryWriter& w) const {
  w.boolean(open_.has_value());
  if (open_) {
    w.size(open_->keyframe);
    w.f64(open_->time);
    writeOptionalImage(w, open_->before);
    writeOptionalImage(w, open_->after);
  }
  w.boolean(previous_time_.has_value());
  if (previous_time_) w.f64(*previous_time_);
  writeOptionalImage(w, latest_);
}

void KeyframeImageAssigner::readState(BinaryReader& r, size_t keyframes) {
  open_.reset();
  if (r.boolean()) {
    Slot s;
    s.keyframe = r.size();
    if (s.keyframe >= keyframes) r.fail("image slot of keyframe " + std::to_string(s.keyframe));
    s.time = r.f64();
    s.before = readOptionalImage(r);
    s.after = readOptionalImage(r);
    open_ = std::move(s);
  }
  previous_time_.reset();
  if (r.boolean()) previous_time_ = r.f64();
  latest_ = readOptionalImage(r);
}

// --- The pipeline ---

void Pipeline::writeStateNow(BinaryWriter& w) const {
  if (finished_) throw std::logic_error("Pipeline::writeState after finish(): that state cannot be continued");
  w.beginSection(kStatsTag);
  writeStats(w, stats_);
  w.boolean(have_first_ts_);
  w.size(reference_.size());
  reference_.forEach([&](const io::StampedPose& p) { StampedPoseCodec::write(w, p); });
  w.endSection();

  w.beginSection(kMapTag);
  map_.writeState(w);
  w.endSection();

  w.beginSection(kFilterTag);
  w.boolean(map_.filter() != nullptr);
  if (map_.filter()) {
    map_.filter()->writeState(w);
    map_.nodes()->writeState(w);
  }
  w.endSection();

  w.beginSection(kLocalTag);
  local_.writeState(w);
  submap_corrections_.writeState(w);
  w.endSection();

  w.beginSection(kGlobalTag);
  global_.writeState(w);
  w.endSection();

  w.beginSection(kImagesTag);
  images_.writeState(w);
  w.size(image_keyframes_.size());
  for (size_t k : image_keyframes_) w.size(k);
  // The Tree of Words database is not saved: a map that has one says so, and is refused.
  w.boolean(image_detector_ != nullptr);
  w.endSection();
}

void Pipeline::readState(BinaryReader& r, std::uint32_t format_version, bool continued) {
  if (map_.size() != 0 || stats_.measurements != 0 || finished_) throw std::logic_error("Pipeline::readState into a pipeline that has run");
  {
    BinaryReader s = r.section(kStatsTag);
    readStats(s, stats_, format_version);
    have_first_ts_ = s.boolean();
    reference_.clear();
    for (size_t i = 0, count = s.count(32); i < count; ++i) reference_.push_back(StampedPoseCodec::read(s));
    s.expectEnd();
  }
  {
    BinaryReader s = r.section(kMapTag);
    map_.readState(s);
    s.expectEnd();
  }
  {
    BinaryReader s = r.section(kFilterTag);
    const bool has_filter = s.boolean();
    if (has_filter != (map_.filter() != nullptr))
      s.fail(has_filter ? "it holds a filter, but [estimator] type is dead_reckoning" : "it holds no filter, but [estimator] type is esdf");
    if (map_.filter()) {
      map_.filter()->readState(s, format_version >= 9, format_version >= 10);
      if (format_version >= 10)
        map_.nodes()->readState(s, map_.size(), format_version);
      else
        map_.nodes()->readOwnPoses(s, map_.size());
    }
    s.expectEnd();
  }
  {
    BinaryReader s = r.section(kLocalTag);
    local_.readState(s, format_version >= 5, format_version >= 13, format_version >= 15);
    submap_corrections_.readState(s);
    s.expectEnd();
  }
  {
    BinaryReader s = r.section(kGlobalTag);
    global_.readState(s, format_version);
    s.expectEnd();
  }
  {
    BinaryReader s = r.section(kImagesTag);
    images_.readState(s, map_.size());
    image_keyframes_.resize(s.count(8));
    for (size_t& k : image_keyframes_) {
      k = s.size();
      if (k >= map_.size()) s.fail("image of keyframe " + std::to_string(k));
    }
    if (s.boolean() && continued)
      throw common::InputError(r.name() +
                               ": built with [loop_closure] image_detector = tree_of_words over camera images; map files do "
                               "not hold the image database, so this map cannot be continued");
    s.expectEnd();
  }
}

}  // namespace urbanslam::slam
