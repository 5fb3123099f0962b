#include "urbanslam/io/RawlogWriter.h"

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <filesystem>
#include <mrpt/obs/CObservationImage.h>

#include "MrptConversions.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;

struct RawlogWriter::Impl {
  std::string path, temp;
  RawlogLayout layout;
  mrpt::io::CFileGZOutputStream out;
  mrpt::obs::CSensoryFrame::Ptr frame;  // SensoryFrames layout: observations since the last odometry
  bool frame_has_scan = false;          // a frame holds one laser scan: a second one starts the next
  bool action_since_frame = false;      // an action was written after the last frame
  bool have_odom = false;
  common::Pose2 last_odom;
  size_t written = 0;
  bool closed = false;
  ImageStorage images = ImageStorage::Embedded;
  std::string images_dir, last_image;
  std::string images_temp;  // the images are written here and the folder renamed at close()
  size_t image_count = 0;

  // The observation for m; an image is first saved beside the rawlog when stored externally.
  mrpt::obs::CObservation::Ptr observation(const Measurement& m) {
    auto o = detail::toMrpt(m);
    const auto* img = std::get_if<CameraImage>(&m);
    if (!img || images != ImageStorage::External) return o;
    auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(o);
    char name[64];
    std::snprintf(name, sizeof name, "_%06zu.png", image_count++);
    last_image = img->label + name;
    const std::string file = images_temp + "/" + last_image;
    if (!obs->image.saveToFile(file)) throw InputError(file + ": cannot write image");
    obs->image.setExternalStorage(last_image);  // drops the pixels; the rawlog keeps the name
    return obs;
  }

  void flushFrame() {
    if (!frame || frame->size() == 0) return;
    auto arch = mrpt::serialization::archiveFrom(out);
    // The classic layout alternates actions and frames (MRPT's readers pair them); a log without
    // odometry (speed + steering, camera only) gets an empty action before each frame.
    if (!action_since_frame) arch << mrpt::obs::CActionCollection();
    arch << *frame;
    frame = mrpt::obs::CSensoryFrame::Create();
    frame_has_scan = false;
    action_since_frame = false;
  }
};

RawlogWriter::RawlogWriter(const std::string& path, RawlogLayout layout, int gz_level, ImageStorage images)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->images = images;
  common::removeStaleTemporaries(path);  // of writers that were killed
  if (images == ImageStorage::External) {
    const std::filesystem::path p(path);
    impl_->images_dir = (p.parent_path() / (p.stem().string() + "_Images")).string();
    common::removeStaleTemporaries(impl_->images_dir);
    // A folder of its own until close(): an interrupted run leaves no images that look like a
    // finished run's, and a rerun never mixes its images with an earlier run's.
    impl_->images_temp = common::temporaryPathFor(impl_->images_dir);
    std::error_code ec;
    std::filesystem::create_directories(impl_->images_temp, ec);
    if (ec) throw InputError(impl_->images_dir + ": cannot create the images folder (" + ec.message() + ")");
  }
  impl_->temp = common::temporaryPathFor(path);
  impl_->layout = layout;
  if (!impl_->out.open(impl_->temp, gz_level)) throw InputError(path + ": cannot write");
  impl_->frame = mrpt::obs::CSensoryFrame::Create();
}

RawlogWriter::~RawlogWriter() {
  if (!impl_->closed) {
    impl_->out.close();
    std::remove(impl_->temp.c_str());
    std::error_code ec;
    if (!impl_->images_temp.empty()) std::filesystem::remove_all(impl_->images_temp, ec);
  }
}

void RawlogWriter::write(const Measurement& m) {
  auto arch = mrpt::serialization::archiveFrom(impl_->out);
  if (impl_->layout == RawlogLayout::Observations) {
    arch << *impl_->observation(m);
  } else if (const auto* od = std::get_if<OdometryReading>(&m)) {
    // Classic layout: the frame gathered so far, then the odometry increment as an action.
    impl_->flushFrame();
    if (impl_->have_odom) {
      const common::Pose2 inc = common::between(impl_->last_odom, od->pose);
      mrpt::obs::CActionRobotMovement2D mv;
      mv.timestamp = detail::toMrptTime(od->timestamp);
      mrpt::obs::CActionRobotMovement2D::TMotionModelOptions opts;
      opts.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
      mv.computeFromOdometry(mrpt::poses::CPose2D(inc.x, inc.y, inc.phi), opts);
      mv.timestamp = detail::toMrptTime(od->timestamp);
      mrpt::obs::CActionCollection acts;
      acts.insert(mv);
      arch << acts;
      impl_->action_since_frame = true;
    }
    impl_->have_odom = true;
    impl_->last_odom = od->pose;
  } else {
    // One scan per frame, as SLAM apps (icp-slam) process a frame as one observation step; a log
    // without odometry would otherwise end up as a single frame.
    const bool scan = std::holds_alternative<LaserScan>(m);
    if (scan && impl_->frame_has_scan) impl_->flushFrame();
    impl_->frame->insert(impl_->observation(m));
    impl_->frame_has_scan = impl_->frame_has_scan || scan;
  }
  ++impl_->written;
}

void RawlogWriter::close() {
  if (impl_->closed) return;
  impl_->flushFrame();
  impl_->out.close();
  if (!impl_->images_temp.empty()) {
    // The images first: the rawlog in place is what marks the output complete.
    std::error_code ec;
    std::filesystem::remove_all(impl_->images_dir, ec);
    std::filesystem::rename(impl_->images_temp, impl_->images_dir, ec);
    if (ec) throw InputError(impl_->images_dir + ": cannot rename the finished images folder into place (" + ec.message() + ")");
  }
  if (std::rename(impl_->temp.c_str(), impl_->path.c_str()) != 0)
    throw InputError(impl_->path + ": cannot rename the finished file into place");
  impl_->closed = true;
}

size_t RawlogWriter::written() const { return impl_->written; }
const std::string& RawlogWriter::lastImageFile() const { return impl_->last_image; }
const std::string& RawlogWriter::imagesFolder() const { return impl_->images_dir; }

}  // namespace urbanslam::io
