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

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "ActionCollection.h"
#include "AllocationLimit.h"
#include "MovementGuard.h"
#include "MrptConversions.h"
#include "TextScanner.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;
namespace fs = std::filesystem;

namespace {

// An MRPT read-only stream over our zlib reader, so we control truncation errors and progress.
// It keeps the first bytes of each entry: the class name of the object being read, for errors.
class GzMrptStream : public mrpt::io::CStream {
 public:
  explicit GzMrptStream(const std::string& path) : in_(detail::openGzFile(path)) {}
  size_t Read(void* buf, size_t n) override {
    const size_t got = rawRead(static_cast<char*>(buf), n);
    const size_t keep = std::min(got, head_.size() - std::min(head_.size(), static_cast<size_t>(pos_ - entry_start_)));
    head_len_ = std::max<size_t>(head_len_, static_cast<size_t>(pos_ - entry_start_) + keep);
    if (keep > 0) std::memcpy(head_.data() + (pos_ - entry_start_), buf, keep);
    pos_ += got;
    if (got == n) {
      movement_.check(static_cast<const unsigned char*>(buf), n);
      checkNesting(static_cast<const unsigned char*>(buf), n);
    }
    return got;
  }
  size_t Write(const void*, size_t) override { throw std::logic_error("read-only stream"); }
  uint64_t Seek(int64_t, TSeekOrigin) override { throw std::logic_error("stream cannot seek"); }
  uint64_t getTotalBytesCount() const override { return 0; }
  uint64_t getPosition() const override { return pos_; }
  // Why the last Read refused a field (MovementGuard, or a container nested in the entry), or "".
  const std::string& refusal() const { return nesting_failure_.empty() ? movement_.failure() : nesting_failure_; }
  double progress() const { return in_->progress(); }

  // The class name of the object header that comes next (MRPT's: length | 0x80, then the
  // name), without consuming it; "" when the next bytes are not such a header.
  std::string peekClassName() {
    if (!peek(1)) return {};
    const auto c = static_cast<unsigned char>(pushback_[0]);
    if (!(c & 0x80)) return {};
    const size_t len = c & 0x7f;
    peek(1 + len);
    return pushback_.substr(1, len);
  }

  void startEntry() {
    entry_start_ = pos_;
    head_len_ = 0;
    containers_ = 0;
    name_length_ = 0;
    nesting_failure_.clear();
  }
  // Class name of the entry's object as MRPT writes it (length | 0x80, then the name), or "".
  std::string entryClass() const {
    if (head_len_ < 1 || !(head_[0] & 0x80)) return {};
    const size_t len = static_cast<unsigned char>(head_[0]) & 0x7f;
    if (len == 0 || head_len_ < 1 + len) return {};
    std::string name(head_.data() + 1, len);
    for (char c : name)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != ':') return {};
    return name;
  }

 private:
  // Makes the next `n` bytes available in pushback_ (fewer at the end of the file).
  bool peek(size_t n) {
    while (pushback_.size() < n) {
      char buf[128];
      const size_t k = in_->read(buf, std::min(sizeof buf, n - pushback_.size()));
      if (k == 0) return false;
      pushback_.append(buf, k);
    }
    return true;
  }

  // From the bytes peeked first, then the file.
  size_t rawRead(char* buf, size_t n) {
    size_t got = std::min(n, pushback_.size());
    std::memcpy(buf, pushback_.data(), got);
    pushback_.erase(0, got);
    while (got < n) {
      const size_t k = in_->read(buf + got, n - got);
      if (k == 0) break;
      got += k;
    }
    return got;
  }

  // A sensory frame or an action collection is an entry of the rawlog, never part of another
  // object: MRPT would read one nested in another all the same (and fail only afterwards, on its
  // type), so a file of frames nested in frames recurses as deep as it is long, and every level
  // rethrows the error with a backtrace of the levels below (seconds, hundreds of megabytes; an
  // allocation refused inside MRPT's what() ends the process). The second such class name read
  // in one entry stops the read there. MRPT reads a class name as one byte (its length | 0x80)
  // and then the name in one read.
  void checkNesting(const unsigned char* data, size_t n) {
    if (n == 1 && (data[0] & 0x80)) {
      name_length_ = data[0] & 0x7f;
      return;
    }
    const size_t expected = name_length_;
    name_length_ = 0;
    if (expected == 0 || n != expected) return;
    const std::string name(reinterpret_cast<const char*>(data), n);
    static const std::array<const char*, 4> kContainers = {"CSensoryFrame", "mrpt::obs::CSensoryFrame", "CActionCollection",
                                                           "mrpt::obs::CActionCollection"};
    if (std::find(kContainers.begin(), kContainers.end(), name) == kContainers.end()) return;
    if (++containers_ < 2) return;
    nesting_failure_ = "a " + name + " inside another sensory frame or action collection";
    throw std::runtime_error(nesting_failure_);
  }

  std::unique_ptr<detail::ByteStream> in_;
  std::string pushback_;
  size_t containers_ = 0, name_length_ = 0;
  std::string nesting_failure_;
  uint64_t pos_ = 0, entry_start_ = 0;
  std::array<char, 130> head_{};
  size_t head_len_ = 0;
  detail::MovementGuard movement_;
};

bool isGzipFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char magic[2] = {0, 0};
  f.read(magic, 2);
  return f.gcount() == 2 && static_cast<unsigned char>(magic[0]) == 0x1f && static_cast<unsigned char>(magic[1]) == 0x8b;
}

// MRPT's messages are a banner, "Message: ...", the location and a backtrace, nested once per
// layer that rethrew: the innermost "Message:" line names the cause ("unknown serialization
// version number: '99'"). Bytes of a corrupt file that it quotes are shown as '?'.
std::string mrptMessage(const std::string& what) {
  std::istringstream in(what);
  std::string line, first, innermost;
  while (std::getline(in, line)) {
    const bool message = line.rfind("Message:", 0) == 0;
    if (message) line.erase(0, 8);
    const auto b = line.find_first_not_of(" \t\r");
    const auto e = line.find_last_not_of(" \t\r");
    if (b == std::string::npos || line.compare(b, 4, "====") == 0 || line.compare(b, 5, "(====") == 0) continue;
    line = line.substr(b, e - b + 1);
    if (message) innermost = line;
    if (first.empty()) first = line;
  }
  std::string out = innermost.empty() ? first : innermost;
  if (out.empty()) out = "unreadable data";
  if (out.size() > 200) out = out.substr(0, 200) + "...";
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return out;
}

// Bounds on what deserialising one entry may allocate (see AllocationLimit.h). The largest
// single block a sane entry needs is an image or a point cloud of some MB (a 100 000-beam scan
// is 0.9 MB, a 4K colour image 25 MB); in a plain file a block also cannot exceed the bytes left
// to fill it (a few times that: MRPT widens some fields as it reads them).
constexpr size_t kMaxBlockBytes = size_t{64} << 20;
constexpr size_t kMaxEntryBytes = size_t{256} << 20;
constexpr size_t kPlainSlackBytes = size_t{1} << 20;
constexpr size_t kPlainExpansion = 4;

std::string formatBytes(uint64_t n) {
  char buf[48];
  if (n >= (uint64_t{1} << 20))
    std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(n) / (1 << 20));
  else
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(n));
  return buf;
}

}  // namespace

struct RawlogReader::Impl {
  std::string path;
  GzMrptStream stream;
  std::deque<Measurement> pending;
  size_t entries = 0, skipped = 0, frames = 0, actions = 0, observations = 0;
  bool have_odom = false;
  common::Pose2 odom;  // chained from action increments
  bool ended = false;

  bool gzip = false;
  uint64_t file_bytes = 0;

  explicit Impl(const std::string& p) : path(p), stream(p) {
    gzip = isGzipFile(p);
    std::error_code ec;
    file_bytes = fs::file_size(p, ec);
  }

  std::string where() const { return path + ": entry " + std::to_string(entries); }

  // The largest block the next entry may allocate: gzip hides how much data is left.
  size_t maxBlockBytes() const {
    if (gzip) return kMaxBlockBytes;
    const uint64_t left = file_bytes > stream.getPosition() ? file_bytes - stream.getPosition() : 0;
    return static_cast<size_t>(std::min<uint64_t>(kMaxBlockBytes, kPlainSlackBytes + kPlainExpansion * left));
  }

  void addObservation(const mrpt::obs::CObservation::Ptr& obs) {
    using namespace mrpt::obs;
    using detail::checkedCoordinate;
    using detail::checkedMagnitude;
    if (!obs) throw InputError(where() + ": corrupt rawlog: a sensory frame holds a null observation");
    const std::string w = where();
    const double t = detail::fromMrptTime(obs->timestamp);
    if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(obs)) {
      pending.emplace_back(detail::fromMrptScan(*scan, w));
    } else if (auto od = std::dynamic_pointer_cast<CObservationOdometry>(obs)) {
      odom = {checkedCoordinate(od->odometry.x(), w, "odometry x"), checkedCoordinate(od->odometry.y(), w, "odometry y"),
              checkedCoordinate(od->odometry.phi(), w, "odometry phi")};
      pending.emplace_back(OdometryReading{t, odom});
      have_odom = true;
    } else if (auto im = std::dynamic_pointer_cast<CObservationImage>(obs)) {
      CameraImage img = detail::toGray(im->image, t, im->sensorLabel, where());
      img.calibration = detail::fromMrptCamera(im->cameraParams, im->cameraPose, img.width, img.height, w);
      pending.emplace_back(std::move(img));
    } else if (auto st = std::dynamic_pointer_cast<CObservationStereoImages>(obs)) {
      pending.emplace_back(detail::toGray(st->imageLeft, t, st->sensorLabel, where()));
    } else if (auto daq = std::dynamic_pointer_cast<CObservationRawDAQ>(obs);
               daq && daq->sensorLabel == detail::kDriveLabel && daq->AIN_double.size() == 2) {
      pending.emplace_back(DriveReading{t, checkedMagnitude(daq->AIN_double[0], w, "drive speed"),
                                        checkedMagnitude(daq->AIN_double[1], w, "drive steering")});
    } else if (auto rp = std::dynamic_pointer_cast<CObservationRobotPose>(obs);
               rp && (rp->sensorLabel == detail::kGpsLabel || rp->sensorLabel == detail::kReferenceLabel)) {
      const auto& m = rp->pose.mean;
      if (rp->sensorLabel == detail::kGpsLabel)
        pending.emplace_back(GpsFix{t, checkedCoordinate(m.x(), w, "GPS x"), checkedCoordinate(m.y(), w, "GPS y")});
      else
        pending.emplace_back(
            ReferencePose{t,
                          {checkedCoordinate(m.x(), w, "reference pose x"), checkedCoordinate(m.y(), w, "reference pose y"),
                           checkedCoordinate(m.yaw(), w, "reference pose yaw")}});
    } else {
      ++skipped;
    }
  }

  void addAction(const mrpt::obs::CActionCollection& acts) {
    // MRPT's getBestMovementEstimation dereferences every action and every movement's PDF.
    for (const auto& a : acts) {
      if (!a.get()) throw InputError(where() + ": corrupt rawlog: an action collection holds a null action");
      if (const auto* m = dynamic_cast<const mrpt::obs::CActionRobotMovement2D*>(a.get()); m && !m->poseChange.get())
        throw InputError(where() + ": corrupt rawlog: a robot movement has no pose change");
    }
    auto mv = acts.getBestMovementEstimation();
    if (!mv) {
      ++skipped;
      return;
    }
    const auto inc = mv->poseChange->getMeanVal();
    const std::string w = where();
    odom = common::compose(
        odom, {detail::checkedCoordinate(inc.x(), w, "odometry increment x"), detail::checkedCoordinate(inc.y(), w, "odometry increment y"),
               detail::checkedCoordinate(inc.phi(), w, "odometry increment phi")});
    detail::checkedCoordinate(odom.x, w, "odometry x");
    detail::checkedCoordinate(odom.y, w, "odometry y");
    have_odom = true;
    pending.emplace_back(OdometryReading{detail::fromMrptTime(mv->timestamp), odom});
  }

  // Reads one more rawlog entry into `pending`; false at the clean end of the file.
  bool readEntry() {
    if (ended) return false;
    auto arch = mrpt::serialization::archiveFrom(stream);
    mrpt::serialization::CSerializable::Ptr obj;
    const uint64_t before = stream.getPosition();
    stream.startEntry();
    const size_t max_block = maxBlockBytes();
    detail::ScopedAllocationLimit limit(max_block, kMaxEntryBytes);
    const auto object = [&] {
      const std::string c = stream.entryClass();
      return c.empty() ? std::string("its object") : "its " + c;
    };
    const auto refusal = [&] {
      const size_t refused = limit.refusedBytes();
      const uint64_t left = file_bytes > before ? file_bytes - before : 0;
      const std::string why =
          refused > max_block
              ? "a block of " + formatBytes(refused) + " (limit " + formatBytes(max_block) +
                    (gzip ? ", the most any sensor reading needs)" : ": the file has " + formatBytes(left) + " left)")
              : formatBytes(limit.allocatedBytes() + refused) + " in all (limit " + formatBytes(kMaxEntryBytes) + " per entry)";
      return InputError(where() + ": corrupt rawlog: " + object() + " declares " + why);
    };
    try {
      const std::string cls = stream.peekClassName();
      obj = cls == "CActionCollection" || cls == "mrpt::obs::CActionCollection" ? detail::readActionCollection(arch, stream, where())
                                                                                : arch.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      ended = true;
      if (stream.getPosition() != before) throw InputError(where() + ": truncated rawlog (file ends inside an entry)");
      if (entries == 0) throw InputError(path + ": empty file (no rawlog entries)");
      return false;
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      if (limit.refusedBytes() > 0) throw refusal();
      const std::string msg = stream.refusal().empty() ? mrptMessage(e.what()) : stream.refusal();
      throw InputError(entries == 0 ? path + ": not an MRPT rawlog (" + msg + ")"
                                    : where() + ": corrupt or truncated rawlog (" + object() + ": " + msg + ")");
    }
    if (limit.refusedBytes() > 0) throw refusal();  // MRPT caught the refusal and read on
    limit.end();                                    // the conversions below are ours, and bounded
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
