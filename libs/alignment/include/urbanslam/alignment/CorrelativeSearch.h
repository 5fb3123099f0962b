#pragma once
// The pose that maximises scan log-likelihood + motion-prior log-density over a search window,
// found exactly by branch and bound over the likelihood grid's levels (Olson 2009; Hess et al.
// 2016): a block of 2^h x 2^h translations at one heading is scored with the level-h grid plus
// the prior's density at the block's pose nearest the prior (an upper bound for every pose in
// the block), and a block is split only while its bound beats the best pose found so far.
// Headings are enumerated at a step that moves the farthest point by about one cell.
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/alignment/LikelihoodGrid.h"
#include "urbanslam/alignment/MotionPrior.h"

namespace urbanslam::alignment {

struct CorrelativeWindow {
  double half_width_m = 1.0;    // translations within +-this of the prior's mean, on each axis
  double half_angle_rad = 0.5;  // headings within +-this of the prior's mean
  // Poses scoring at most this are of no interest to the caller (a place search that only needs
  // the poses near its best so far): blocks bounded below it are not searched, and when no pose
  // beats it the result says so (below_min_score) instead of naming the best.
  double min_score = -HUGE_VAL;
  // The prior's density is the same everywhere in the window (a place search with no idea of
  // the pose): it is taken once, at the prior's mean, instead of bounded block by block (a sixth
  // of a place search's time went into those bounds).
  bool flat_prior = false;
  // The window cut short by this much on its -x, +x, -y and +y side (each at most half_width_m;
  // the prior's mean stays inside): a place search leaves out what a neighbouring window covers.
  std::array<double, 4> trim_m{{0.0, 0.0, 0.0, 0.0}};
};

struct CorrelativeResult {
  common::Pose2 pose;
  double score = 0;              // scan log-likelihood + prior log-density at pose
  double scan_score = 0;         // the scan's share of it
  int nodes = 0;                 // blocks scored (the search's cost)
  bool below_min_score = false;  // no pose scored above the window's min_score: pose and scores say nothing
};

// points: the scan's points in its own frame (thinned so they are roughly independent).
CorrelativeResult correlativeSearch(const LikelihoodGrid& grid, const std::vector<Eigen::Vector2d>& points, const MotionPrior& prior,
                                    const CorrelativeWindow& window);

}  // namespace urbanslam::alignment
