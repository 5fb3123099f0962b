#pragma once
// Writes measurements as an MRPT rawlog (gzip-compressed, as MRPT's own tools write them) that
// RawLogViewer and rawlog-edit open. Written to a temporary name; close() renames it into
// place, so an interrupted conversion leaves no file that looks complete.
#include <memory>
#include <string>

#include "urbanslam/io/Measurements.h"

namespace urbanslam::io {

enum class RawlogLayout {
  Observations,   // one CObservation per entry (MRPT's modern layout)
  SensoryFrames,  // CActionCollection (odometry increment) / CSensoryFrame pairs (classic)
};

enum class ImageStorage {
  Embedded,  // pixels inside the rawlog
  External,  // PNG files in "<rawlog name>_Images/" beside it, referenced by name (MRPT's
             // convention, which RawlogViewer and our reader follow): rawlogs stay small
};

class RawlogWriter {
 public:
  RawlogWriter(const std::string& path, RawlogLayout layout, int gz_level = 5, ImageStorage images = ImageStorage::Embedded);
  ~RawlogWriter();
  void write(const Measurement& m);
  // Flushes and renames into place. Without close(), the temporary file is removed.
  void close();
  size_t written() const;
  // External images: the file name (inside the images folder) of the last image written, named
  // "<label>_<number>.png" in order of writing.
  const std::string& lastImageFile() const;
  // The images folder (External), created by the constructor.
  const std::string& imagesFolder() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace urbanslam::io
