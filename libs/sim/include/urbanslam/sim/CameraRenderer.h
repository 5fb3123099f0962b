#pragma once
// A pinhole camera looking horizontally into the city, rendered by column ray casting: each image
// column casts one ray in the camera's horizontal plane through the city's walls; every wall it
// meets stands on the ground with its look's height, so it fills the rows between its foot and
// its top (height ∝ 1/depth) with its procedural texture. Low objects (cars, trees, posts) let
// the ray go on, and what lies behind shows above them. Sky above, textured ground below, a
// fixed sun shading each wall by its orientation, distance fog and pixel noise. Moving traffic is
// not drawn. Each image's noise comes from its own index, so an image is reproducible on its own.
#include <cstdint>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

class CameraRenderer {
 public:
  // seed: the city's (the ground's paving and the noise follow from it).
  CameraRenderer(const CameraOptions& options, const WallRayCaster& walls, uint64_t seed);

  // Image number `index` (its noise) seen from the camera's pose in the world (camera frame: x
  // forward, y left; the mounting already applied).
  io::CameraImage render(uint64_t index, double timestamp, const common::Pose2& camera) const;

  // The depth-free distance along each column's ray to the first wall, or kNoHit: what the
  // camera sees of the map, for ground-truth view overlap.
  std::vector<double> columnRanges(const common::Pose2& camera) const;
  // Bearing of column x's ray in the camera frame (counter-clockwise; the left edge is positive).
  double columnBearing(int x) const;

  double fx() const { return fx_; }
  double fy() const { return fx_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }

 private:
  CameraOptions options_;
  const WallRayCaster& walls_;
  uint64_t seed_, ground_seed_;
  double fx_, cx_, cy_;
  std::vector<double> bearing_;  // per column
};

}  // namespace urbanslam::sim
