#pragma once
// Error of an estimated pose graph against ground truth: absolute trajectory error (RMSE of
// the positions after the best rigid 2D alignment, no scale) and the mean absolute heading
// error after the same alignment. Poses are matched by vertex id; the alignment removes the
// gauge (an optimiser may fix any vertex anywhere).
#include <string>
#include <vector>

#include "urbanslam/esdf/PoseGraphIO.h"

namespace urbanslam::esdf {

struct TrajectoryError {
  size_t matched = 0;  // vertex ids present in both
  double ate_rmse_m = 0, ate_max_m = 0;
  double heading_mean_abs_rad = 0, heading_max_abs_rad = 0;
  Vec3 alignment = Vec3::Zero();  // (tx, ty, theta) mapping the estimate onto the reference
};

// Throws common::InputError when fewer than two ids match.
TrajectoryError trajectoryError(const std::vector<PoseGraphVertex>& estimate, const std::vector<PoseGraphVertex>& reference);

// Reference poses: a pose graph with VERTEX lines (g2o / TORO), or a text file with one pose a
// line, "id x y theta" or "x y theta" (the id is then the line's index among the poses).
std::vector<PoseGraphVertex> readReferencePoses(const std::string& path);

}  // namespace urbanslam::esdf
