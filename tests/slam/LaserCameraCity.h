#pragma once
// A small simulated city driven by a car with the front 180° laser of ini/city-1km2.ini and the
// left-looking camera of ini/city-camera.ini (0.25 km², a 1.5 km drive), and the shipped
// pipeline with the ORB vocabulary (a sixth of SIFT's time): the setting of the tests that need
// both sensors on real pipeline runs.
#include "TestPaths.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::test {

inline sim::SimOptions laserCameraCity() {
  sim::SimOptions so = sim::loadSimOptions(repoPath("ini/city-1km2.ini"));
  so.camera = sim::loadSimOptions(repoPath("ini/city-camera.ini")).camera;
  so.city.area_km2 = 0.25;
  so.route.route_length_km = 1.5;
  return so;
}

inline slam::PipelineOptions laserCameraPipeline() {
  slam::PipelineOptions po = slam::loadPipelineOptions(repoPath("ini/default.ini"));
  slam::resolveDefaultPaths(po, URBANSLAM_SOURCE_DIR);
  po.image_loop.vocabulary = repoPath("share/vision_loop/orb_k10_L4.usvoc");
  return po;
}

}  // namespace urbanslam::test
