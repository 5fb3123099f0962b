#pragma once
// Vehicle motion models of thesis section 2.2, each x(k+1) = f(x(k), u(k+1)) with analytic
// Jacobians F_x = df/dx and F_u = df/du, and the process noise of section 2.2.4.
#include <Eigen/Core>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

using MatU = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3>;               // F_u: 3 x (2 or 3), no heap
using VecU = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;               // u: 2 or 3 inputs
using MatQ = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;  // Q_v

class MotionModel {
 public:
  virtual ~MotionModel() = default;
  // Number of inputs u (2 for the vehicle models, 3 for the laser/odometry model).
  virtual int inputDimension() const = 0;
  // f(x, u) over a time step dt_s; fills F_x and F_u when non-null. The heading of the result
  // is not wrapped (the filter's chart is continuous, see PoseOps.h).
  virtual Vec3 predict(const Vec3& x, const VecU& u, double dt_s, Mat3* f_x, MatU* f_u) const = 0;
};

// Steering model, eqs. 2.10-2.12: u = (speed m/s, steering angle rad), pose at the vehicle centre.
struct SteeringModelOptions {
  double wheelbase_m = 2.83;  // WB; default: the Victoria Park car's L
};
class SteeringModel : public MotionModel {
 public:
  explicit SteeringModel(SteeringModelOptions o = {}) : opt_(o) {}
  int inputDimension() const override { return 2; }
  Vec3 predict(const Vec3& x, const VecU& u, double dt_s, Mat3* f_x, MatU* f_u) const override;

 private:
  SteeringModelOptions opt_;
};

// Turn-rate model, eqs. 2.13-2.15: u = (speed m/s, turn rate rad/s), pose at the laser, which
// sits at offsets a, b (and h) from the reference point. Defaults: the Victoria Park car
// (a = 0.95 m, b = 0.5 m, H = 0.76 m; /work/shared/data/victoria_park/info.txt).
struct TurnRateModelOptions {
  double laser_offset_a_m = 0.95;
  double laser_offset_b_m = 0.5;
  double laser_offset_h_m = 0.76;
};
class TurnRateModel : public MotionModel {
 public:
  explicit TurnRateModel(TurnRateModelOptions o = {}) : opt_(o) {}
  int inputDimension() const override { return 2; }
  Vec3 predict(const Vec3& x, const VecU& u, double dt_s, Mat3* f_x, MatU* f_u) const override;

 private:
  TurnRateModelOptions opt_;
};

// Laser/odometry model, eqs. 2.16-2.18: x ⊕ u with u = (dx, dy, dphi) in the vehicle frame;
// F_x = J1⊕, F_u = J2⊕. dt is ignored.
class OdometryModel : public MotionModel {
 public:
  int inputDimension() const override { return 3; }
  Vec3 predict(const Vec3& x, const VecU& u, double dt_s, Mat3* f_x, MatU* f_u) const override;
};

// Process noise in the pose space, Q = Q_s + F_u Q_v F_u' (Q_s = diag(q_s), eq. 2.21), for the
// covariance-form reference.
Mat3 processCovariance(const MatU& f_u, const MatQ& q_v, const Vec3& stabilising_noise);

// Q^{-1} as the information filter needs it. With two inputs F_u Q_v F_u' has rank 2 and no
// inverse; the stabilising noise Q_s makes it invertible and the matrix inversion lemma
// (eq. 2.20) inverts only diagonal and 2x2 matrices:
//   (Q_s + F_u Q_v F_u')^-1 = Q_s^-1 - Q_s^-1 F_u (Q_v^-1 + F_u' Q_s^-1 F_u)^-1 F_u' Q_s^-1.
// With a zero Q_s (allowed when F_u Q_v F_u' is already invertible, e.g. the odometry model)
// the direct inverse is used.
Mat3 processInformation(const MatU& f_u, const MatQ& q_v, const Vec3& stabilising_noise);

}  // namespace urbanslam::esdf
