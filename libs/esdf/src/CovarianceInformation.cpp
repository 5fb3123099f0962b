#include "urbanslam/esdf/CovarianceInformation.h"

#include <Eigen/Dense>
#include <stdexcept>

namespace urbanslam::esdf {

InformationForm informationFromCovariance(const Eigen::MatrixXd& p, const Eigen::VectorXd& x, int nv) {
  const int n = static_cast<int>(p.rows());
  if (p.cols() != n || x.size() != n || nv < 1 || nv > n) throw std::invalid_argument("informationFromCovariance: sizes");
  const int nt = n - nv;
  InformationForm out;
  out.lambda.resize(n, n);
  out.eta.resize(n);
  if (nt == 0) {
    out.lambda = p.inverse();
    out.eta = out.lambda * x;
    return out;
  }
  const Eigen::MatrixXd ptt = p.topLeftCorner(nt, nt), ptv = p.topRightCorner(nt, nv);
  const Eigen::MatrixXd pvt = p.bottomLeftCorner(nv, nt), pvv = p.bottomRightCorner(nv, nv);
  const Eigen::LDLT<Eigen::MatrixXd> ptt_f(ptt);
  const Eigen::MatrixXd ptt_inv = ptt_f.solve(Eigen::MatrixXd::Identity(nt, nt));
  const Eigen::MatrixXd delta = pvv - pvt * ptt_inv * ptv;  // eq. 2.8
  const Eigen::MatrixXd di = delta.ldlt().solve(Eigen::MatrixXd::Identity(nv, nv));
  const Eigen::MatrixXd g = ptt_inv * ptv * di;  // P_tt^-1 P_tv Delta^-1
  // eq. 2.7
  out.lambda.topLeftCorner(nt, nt) = ptt_inv + g * pvt * ptt_inv;
  out.lambda.topRightCorner(nt, nv) = -g;
  out.lambda.bottomLeftCorner(nv, nt) = -g.transpose();
  out.lambda.bottomRightCorner(nv, nv) = di;
  // eq. 2.9
  const Eigen::VectorXd xt = x.head(nt), xv = x.tail(nv);
  out.eta.head(nt) = ptt_inv * (xt + ptv * di * pvt * ptt_inv * xt - ptv * di * xv);
  out.eta.tail(nv) = di * (-pvt * ptt_inv * xt + xv);
  return out;
}

}  // namespace urbanslam::esdf
