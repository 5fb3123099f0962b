#pragma once
// MRPT rawlogs, streamed object by object (never loaded whole), in both layouts: action /
// sensory-frame pairs and observations only, gzipped or not. Unlike
// CRawlog::getActionObservationPairOrObservation, a leading sensory frame without an action and a
// trailing action without a frame are kept. Odometry comes from CActionRobotMovement2D
// increments (chained) or CObservationOdometry.
#include <memory>
#include <string>

#include "urbanslam/io/DataSource.h"

namespace urbanslam::io {

class RawlogReader : public DataSource {
 public:
  explicit RawlogReader(const std::string& path);
  ~RawlogReader() override;
  bool next(Measurement& out) override;
  double progress() const override;
  std::string format() const override;

  // Counts so far: entries read, and observations of classes we do not use (skipped).
  size_t entries() const;
  size_t skippedObservations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace urbanslam::io
