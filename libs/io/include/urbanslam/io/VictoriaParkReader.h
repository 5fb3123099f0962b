#pragma once
// The ACFR Victoria Park car log (Guivant & Nebot): LASER.txt (no newlines: records of
// time_s + 361 ranges in metres, beam k at (k-1)*0.5° from the car's right to its left, 81.91 =
// no return), DRS.txt (time_s speed_m/s steering_rad) and GPS.txt (time_s y_m x_m), merged in
// time order. Reads a folder holding the three files or the original victoria_park_ascii.zip.
#include <memory>
#include <string>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/DataSource.h"

namespace urbanslam::io {

struct VictoriaParkGeometry {
  // Laser mount in the vehicle frame (origin at the centre of the rear axle, x forward):
  // a = 0.95 m ahead of the rear axle and b = 0.5 m to the side (ACFR info.txt: a, b, H, L).
  double laser_x_m = 0.95;
  double laser_y_m = 0.5;
  double max_range_m = 80.0;  // ACFR: ranges above 80 m are "no reflexion"
};

class VictoriaParkReader : public DataSource {
 public:
  explicit VictoriaParkReader(const std::string& path, VictoriaParkGeometry geometry = {});
  ~VictoriaParkReader() override;
  bool next(Measurement& out) override;
  double progress() const override;
  std::string format() const override { return "Victoria Park (ACFR ASCII)"; }

  // True when `path` is a folder with LASER.txt, or a zip named like the ACFR release.
  static bool looksLike(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace urbanslam::io
