#include "urbanslam/io/RawlogReader.h"

#include <mrpt/img/CImage.h>
#include <mrpt/io/CStream.h>
#include <mrpt/maps/registerAllClasses.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <deque>
#include <filesystem>

#include "MrptConversions.h"
#include "TextScanner.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;
namespace fs = std::filesystem;

namespace {

// An MRPT read-only stream over our zlib reader, so we control truncation errors and progress.
class GzMrptStream : public mrpt::io::CStream {
 public:
  explicit GzMrptStream(const std::string& path) : in_(detail::openGzFile(path)) {}
  size_t Read(void* buf, size_t n) override {
    size_t got = 0;
    while (got < n) {
      const size_t k = in_->read(static_cast<char*>(buf) + got, n - got);
      if (k == 0) break;
      got += k;
    }
    pos_ += got;
    return got;
  }
  size_t Write(const void*, size_t) override { throw std::logic_error("read-only stream"); }
  uint64_t Seek(int64_t, TSeekOrigin) override { throw std::logic_error("stream cannot seek"); }
  uint64_t getTotalBytesCount() const override { return 0; }
  uint64_t getPosition() const override { return pos_; }
  double progress() const { return in_->progress(); }

 private:
  std::unique_ptr<detail::ByteStream> in_;
  uint64_t pos_ = 0;
};

}  // namespace

struct RawlogReader::Impl {
  std::string path;
  GzMrptStream stream;
  std::deque<Measurement> pending;
  size_t entries = 0, skipped = 0, frames = 0, actions = 0, observations = 0;
  bool have_odom = false;
  common::Pose2 odom;  // chained from action increments
  bool ended = false;

  explicit Impl(const std::string& p) : path(p), stream(p) {}

  std::string where() const { return path + ": entry " + std::to_string(entries); }

  void addObservation(const mrpt::obs::CObservation::Ptr& obs) {
    using namespace mrpt::obs;
    const double t = detail::fromMrptTime(obs->timestamp);
    if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(obs)) {
      pending.emplace_back(detail::fromMrptScan(*scan, where()));
    } else if (auto od = std::dynamic_pointer_cast<CObservationOdometry>(obs)) {
      pending.emplace_back(OdometryReading{t, {od->odometry.x(), od->odometry.y(), od->odometry.phi()}});
      have_odom = true;
      odom = {od->odometry.x(), od->odometry.y(), od->odometry.phi()};
    } else if (auto im = std::dynamic_pointer_cast<CObservationImage>(obs)) {
      pending.emplace_back(detail::toGray(im->image, t, im->sensorLabel, where()));
    } else if (auto st = std::dynamic_pointer_cast<CObservationStereoImages>(obs)) {
      pending.emplace_back(detail::toGray(st->imageLeft, t, st->sensorLabel, where()));
    } else if (auto daq = std::dynamic_pointer_cast<CObservationRawDAQ>(obs);
               daq && daq->sensorLabel == detail::kDriveLabel && daq->AIN_double.size() == 2) {
      pending.emplace_back(DriveReading{t, daq->AIN_double[0], daq->AIN_double[1]});
    } else if (auto rp = std::dynamic_pointer_cast<CObservationRobotPose>(obs);
               rp && (rp->sensorLabel == detail::kGpsLabel || rp->sensorLabel == detail::kReferenceLabel)) {
      if (rp->sensorLabel == detail::kGpsLabel)
        pending.emplace_back(GpsFix{t, rp->pose.mean.x(), rp->pose.mean.y()});
      else
        pending.emplace_back(ReferencePose{t, {rp->pose.mean.x(), rp->pose.mean.y(), rp->pose.mean.yaw()}});
    } else {
      ++skipped;
    }
  }

  void addAction(const mrpt::obs::CActionCollection& acts) {
    auto mv = acts.getBestMovementEstimation();
    if (!mv) {
      ++skipped;
      return;
    }
    const auto inc = mv->poseChange->getMeanVal();
    odom = common::compose(odom, {inc.x(), inc.y(), inc.phi()});
    have_odom = true;
    pending.emplace_back(OdometryReading{detail::fromMrptTime(mv->timestamp), odom});
  }

  // Reads one more rawlog entry into `pending`; false at the clean end of the file.
  bool readEntry() {
    if (ended) return false;
    auto arch = mrpt::serialization::archiveFrom(stream);
    mrpt::serialization::CSerializable::Ptr obj;
    const uint64_t before = stream.getPosition();
    try {
      obj = arch.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      ended = true;
      if (stream.getPosition() != before) throw InputError(where() + ": truncated rawlog (file ends inside an entry)");
      if (entries == 0) throw InputError(path + ": empty file (no rawlog entries)");
      return false;
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      std::string msg = e.what();
      if (const auto nl = msg.find('\n'); nl != std::string::npos) msg = msg.substr(0, nl);
      throw InputError(entries == 0 ? path + ": not an MRPT rawlog (" + msg + ")"
                                    : where() + ": corrupt or truncated rawlog (" + msg + ")");
    }
    ++entries;
    using namespace mrpt::obs;
    if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(obj)) {
      ++frames;
      for (const auto& o : *sf) addObservation(o);
    } else if (auto acts = std::dynamic_pointer_cast<CActionCollection>(obj)) {
      ++actions;
      addAction(*acts);
    } else if (auto o = std::dynamic_pointer_cast<CObservation>(obj)) {
      ++observations;
      addObservation(o);
    } else {
      throw InputError(where() + ": unexpected object of class " + std::string(obj ? obj->GetRuntimeClass()->className : "null") +
                       " (not a rawlog?)");
    }
    return true;
  }
};

RawlogReader::RawlogReader(const std::string& path) : DataSource(path) {
  // Classes like CObservationRotatingScan live in mrpt-maps; register them or reading fails.
  mrpt::maps::registerAllClasses_mrpt_maps();
  // Externally stored images sit in "<rawlog name>_Images/" beside the rawlog (MRPT convention).
  const fs::path p(path);
  mrpt::img::CImage::setImagesPathBase((p.parent_path() / (p.stem().string() + "_Images")).string());
  impl_ = std::make_unique<Impl>(path);
}

RawlogReader::~RawlogReader() = default;

bool RawlogReader::next(Measurement& out) {
  while (impl_->pending.empty())
    if (!impl_->readEntry()) return false;
  out = std::move(impl_->pending.front());
  impl_->pending.pop_front();
  return true;
}

double RawlogReader::progress() const { return impl_->stream.progress(); }

std::string RawlogReader::format() const {
  if (impl_->frames + impl_->actions > 0) return "MRPT rawlog (actions/sensory frames)";
  return "MRPT rawlog (observations)";
}

size_t RawlogReader::entries() const { return impl_->entries; }
size_t RawlogReader::skippedObservations() const { return impl_->skipped; }

}  // namespace urbanslam::io
