#pragma once
// Thesis section 2.1.2: the covariance <-> information relationships of the delayed state
// X = [x_t; x_v] (history poses, current pose), eqs. 2.5-2.9, via the block inverse with the
// Schur complement Delta = P_vv - P_vt P_tt^-1 P_tv. Dense: for tests and small problems (the
// filter itself never forms P).
#include <Eigen/Core>

namespace urbanslam::esdf {

struct InformationForm {
  Eigen::MatrixXd lambda;  // Lambda = P^-1 (eq. 2.6), by blocks as in eq. 2.7
  Eigen::VectorXd eta;     // eta = Lambda X (eq. 2.5), by blocks as in eq. 2.9
};

// The last `current_dim` entries of x are x_v; the rest x_t (which may be empty).
InformationForm informationFromCovariance(const Eigen::MatrixXd& p, const Eigen::VectorXd& x, int current_dim = 3);

}  // namespace urbanslam::esdf
