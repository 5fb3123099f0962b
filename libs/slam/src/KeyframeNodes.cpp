#include "urbanslam/slam/KeyframeNodes.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "urbanslam/esdf/Gating.h"

namespace urbanslam::slam {

using esdf::Mat3;
using esdf::Vec3;

namespace {

// A relative-pose measurement's noise is on its right, as the filter's edge error has it
// (x_b = x_a ⊕ z ⊕ noise, esdf::relativePoseError); offsets carry theirs added to the offset. The
// one is the other turned by the measurement's heading.
Mat3 rightToAdded(const Vec3& z, const Mat3& cov) {
  Mat3 g;
  esdf::composeJacobians(z, Vec3::Zero(), nullptr, &g);
  return g * cov * g.transpose();
}
Mat3 addedToRight(const Vec3& z, const Mat3& cov) { return rightToAdded(esdf::inverse(z), cov); }

}  // namespace

KeyframeNodes::KeyframeNodes(esdf::Esdf& filter, bool reduced, size_t own_poses_first)
    : filter_(filter), reduced_(reduced), own_poses_first_(own_poses_first) {}

KeyframeNodes::Hang KeyframeNodes::beyond(const Hang& h, const Vec3& z, const Mat3& cov) {
  Hang out;
  out.node = h.node;
  out.hung = true;
  Mat3 j1, j2;
  esdf::composeJacobians(h.offset, z, &j1, &j2);
  out.offset = esdf::compose(h.offset, z);
  out.cov = j1 * h.cov * j1.transpose() + j2 * rightToAdded(z, cov) * j2.transpose();
  return out;
}

void KeyframeNodes::addFirst() {
  if (!reduced_) return;
  hangs_.push_back(Hang{filter_.size() - 1, false, Vec3::Zero(), Mat3::Zero()});
  uses_.push_back(0);
}

bool KeyframeNodes::add(size_t from, const Vec3& z, const Mat3& omega) {
  if (!reduced_) {
    filter_.augmentRelative(static_cast<int>(from), z, omega);
    return true;
  }
  if (from + 1 == size() && size() >= own_poses_first_ && tail_ + 1 < kKeyframesPerPose) {
    hangs_.push_back(beyond(hangs_.at(from), z, omega.inverse()));
    ++tail_;
    return false;
  }
  const Hang& f = hangs_.at(from);
  if (!f.hung) {
    filter_.augmentRelative(f.node, z, omega);
  } else {
    // The link to the new pose: the group's constraints composed, with the share of their
    // information that closures of the group's hung keyframes do not take (kReserved).
    Hang h = beyond(f, z, omega.inverse());
    h.cov /= 1 - kReserved;
    filter_.augmentRelative(h.node, h.offset, addedToRight(h.offset, h.cov).inverse());
  }
  hangs_.push_back(Hang{filter_.size() - 1, false, Vec3::Zero(), Mat3::Zero()});
  uses_.push_back(0);
  tail_ = 0;
  return true;
}

Vec3 KeyframeNodes::mean(size_t k) const {
  if (!hung(k)) return filter_.mean(node(k));
  const Hang& h = hangs_[k];
  return esdf::compose(filter_.mean(h.node), h.offset);
}

Mat3 KeyframeNodes::marginalCovariance(size_t k, esdf::CovarianceMode mode) {
  if (!hung(k)) return filter_.marginalCovariance(node(k), mode);
  const Hang& h = hangs_[k];
  Mat3 j1, j2;
  esdf::composeJacobians(filter_.mean(h.node), h.offset, &j1, &j2);
  return j1 * filter_.marginalCovariance(h.node, mode) * j1.transpose() + j2 * h.cov * j2.transpose();
}

Mat3 KeyframeNodes::relativeCovariance(size_t i, size_t k, esdf::CovarianceMode mode) {
  if (!hung(i) && !hung(k)) return filter_.relativeCovariance(node(i), node(k), mode);
  const Hang& hi = hangs_[i];
  const Hang& hk = hangs_[k];
  // ⊖x_i ⊕ x_k = ⊖o_i ⊕ r ⊕ o_k with r = ⊖x_a ⊕ x_b, the relative pose of the two filter poses.
  const bool apart = hi.node != hk.node;
  const Vec3 r = apart ? esdf::between(filter_.mean(hi.node), filter_.mean(hk.node)) : Vec3::Zero();
  // Hung keyframes' poses are mostly factored ones a few factors apart: the factors on the path
  // between them bound their relative pose (conservative) with no column solve over the map.
  Mat3 r_cov = Mat3::Zero();
  if (apart && !(mode == esdf::CovarianceMode::Conservative && filter_.pathRelativeCovariance(hi.node, hk.node, &r_cov)))
    r_cov = filter_.relativeCovariance(hi.node, hk.node, mode);
  const Vec3 inv_i = esdf::inverse(hi.offset);
  Mat3 a1, a2, b1, b2;
  esdf::composeJacobians(inv_i, r, &a1, &a2);
  esdf::composeJacobians(esdf::compose(inv_i, r), hk.offset, &b1, &b2);
  const Mat3 d_r = b1 * a2, d_i = b1 * a1 * esdf::inverseJacobian(hi.offset);
  return d_r * r_cov * d_r.transpose() + d_i * hi.cov * d_i.transpose() + b2 * hk.cov * b2.transpose();
}

void KeyframeNodes::toNodes(size_t i, size_t k, const Vec3& z, const Mat3& cov, double scale_i, double scale_k, Vec3* z_nodes,
                            Mat3* cov_nodes) const {
  const Hang& hi = hangs_[i];
  const Hang& hk = hangs_[k];
  // x_k = x_i ⊕ z, so x_b = x_a ⊕ (o_i ⊕ z ⊕ ⊖o_k).
  Mat3 c1, c2, d1, d2;
  const Vec3 v = esdf::compose(hi.offset, z);
  esdf::composeJacobians(hi.offset, z, &c1, &c2);
  const Vec3 inv_k = esdf::inverse(hk.offset);
  esdf::composeJacobians(v, inv_k, &d1, &d2);
  *z_nodes = esdf::compose(v, inv_k);
  const Mat3 d_z = d1 * c2, d_i = d1 * c1, d_k = d2 * esdf::inverseJacobian(hk.offset);
  const Mat3 added = d_z * rightToAdded(z, cov) * d_z.transpose() + scale_i * d_i * hi.cov * d_i.transpose() +
                     scale_k * d_k * hk.cov * d_k.transpose();
  *cov_nodes = addedToRight(*z_nodes, added);
}

esdf::GateResult KeyframeNodes::gateWithinNode(size_t i, size_t k, const Vec3& z, const Mat3& omega) const {
  const Hang& hi = hangs_[i];
  const Hang& hk = hangs_[k];
  Eigen::Matrix<double, 6, 6> joint = Eigen::Matrix<double, 6, 6>::Zero();
  joint.topLeftCorner<3, 3>() = hi.cov;
  joint.bottomRightCorner<3, 3>() = hk.cov;
  // As the filter's gate: e = ⊖z ⊕ r, its covariance the relative pose's turned into z's frame
  // plus the measurement's.
  const Mat3 s = addedToRight(z, esdf::betweenCovariance(hi.offset, hk.offset, joint)) + omega.inverse();
  const Eigen::VectorXd nu = -esdf::relativePoseError(hi.offset, hk.offset, z);
  return esdf::mahalanobisGateAt(nu, s, filter_.gateThreshold());
}

double KeyframeNodes::offsetScale(size_t k) const {
  // The u-th closure through a group's offsets takes them with 2^(u+1) / kReserved times their
  // covariance: the shares 1/2, 1/4, ... of the reserve, never more than it in all.
  return hung(k) ? std::ldexp(1.0, uses_[static_cast<size_t>(hangs_[k].node)] + 1) / kReserved : 1.0;
}

esdf::ObservationResult KeyframeNodes::observeRelative(size_t i, size_t k, const Vec3& z, const Mat3& omega, bool gate) {
  if (!hung(i) && !hung(k)) return filter_.observeRelative(node(i), node(k), z, omega, gate);
  esdf::ObservationResult r;
  if (gate) {
    r.gate = gateRelative(i, k, z, omega);
    r.accepted = r.gate.accepted;
  }
  const double scale_i = offsetScale(i), scale_k = offsetScale(k);
  if (!r.accepted || hangs_[i].node == hangs_[k].node || std::max(scale_i, scale_k) > kMaxOffsetScale) return r;
  Vec3 zn;
  Mat3 cn;
  toNodes(i, k, z, omega.inverse(), scale_i, scale_k, &zn, &cn);
  r.chi2 = filter_.observeRelative(hangs_[i].node, hangs_[k].node, zn, cn.inverse(), false).chi2;
  for (const size_t x : {i, k})
    if (hung(x)) ++uses_[static_cast<size_t>(hangs_[x].node)];
  return r;
}

esdf::GateResult KeyframeNodes::gateRelative(size_t i, size_t k, const Vec3& z, const Mat3& omega) { return *gate(i, k, z, omega, false); }

std::optional<esdf::GateResult> KeyframeNodes::refusalWithoutFactorising(size_t i, size_t k, const Vec3& z, const Mat3& omega) {
  std::optional<esdf::GateResult> r = gate(i, k, z, omega, true);
  if (r && r->accepted) r.reset();
  return r;
}

std::optional<esdf::GateResult> KeyframeNodes::gate(size_t i, size_t k, const Vec3& z, const Mat3& omega, bool without_factorising) {
  // The filter's gate on the closure of the filter poses the two keyframes are or hang from;
  // two keyframes hung from one pose are judged by their offsets alone (no map covariance).
  int a, b;
  Vec3 zn;
  Mat3 on;
  if (!onNodes(i, k, z, omega, &a, &b, &zn, &on)) return gateWithinNode(i, k, z, omega);
  if (without_factorising) return filter_.refusalWithoutFactorising(a, b, zn, on);
  return filter_.gateRelative(a, b, zn, on);
}

bool KeyframeNodes::onNodes(size_t i, size_t k, const Vec3& z, const Mat3& omega, int* a, int* b, Vec3* z_nodes, Mat3* omega_nodes) const {
  if (!hung(i) && !hung(k)) {
    *a = node(i), *b = node(k), *z_nodes = z, *omega_nodes = omega;
    return true;
  }
  if (hangs_[i].node == hangs_[k].node) return false;
  Mat3 cn;
  toNodes(i, k, z, omega.inverse(), 1.0, 1.0, z_nodes, &cn);
  *a = hangs_[i].node, *b = hangs_[k].node, *omega_nodes = cn.inverse();
  return true;
}

esdf::GateResult KeyframeNodes::gateRelativePair(size_t i1, size_t k1, const Vec3& z1, const Mat3& omega1, size_t i2, size_t k2,
                                                 const Vec3& z2, const Mat3& omega2) {
  int a1, b1, a2, b2;
  Vec3 zn1, zn2;
  Mat3 on1, on2;
  if (!onNodes(i1, k1, z1, omega1, &a1, &b1, &zn1, &on1) || !onNodes(i2, k2, z2, omega2, &a2, &b2, &zn2, &on2)) {
    esdf::GateResult refused;
    refused.accepted = false;
    return refused;
  }
  return filter_.gateRelativePair(a1, b1, zn1, on1, a2, b2, zn2, on2);
}

void KeyframeNodes::writeState(common::BinaryWriter& w) const {
  w.boolean(reduced_);
  if (!reduced_) return;
  w.size(hangs_.size());
  for (const Hang& h : hangs_) {
    w.i32(h.node);
    w.boolean(h.hung);
    if (!h.hung) continue;
    w.matrix(h.offset);
    w.matrix(h.cov);
  }
  w.size(tail_);
  w.size(uses_.size());
  for (const std::uint8_t u : uses_) w.u8(u);
}

void KeyframeNodes::readOwnPoses(common::BinaryReader& r, size_t keyframes) {
  if (static_cast<size_t>(filter_.size()) != keyframes)
    r.fail("a filter of " + std::to_string(filter_.size()) + " poses for " + std::to_string(keyframes) + " keyframes");
  hangs_.clear();
  tail_ = 0;
  uses_.clear();
  if (!reduced_) return;
  for (size_t k = 0; k < keyframes; ++k) hangs_.push_back(Hang{static_cast<int>(k), false, Vec3::Zero(), Mat3::Zero()});
  uses_.assign(keyframes, 0);
}

void KeyframeNodes::readState(common::BinaryReader& r, size_t keyframes, std::uint32_t format_version) {
  const bool reduced = r.boolean();
  if (reduced && format_version < 11)
    r.fail("keyframes hung from the filter's poses at their closures (map format " + std::to_string(format_version) +
           "), which this version no longer reads: map the log again");
  if (reduced != reduced_)
    r.fail(reduced ? "keyframes hang from others' filter poses, but [estimator] reduced_pose_graph is false"
                   : "every keyframe has a pose of its own, but [estimator] reduced_pose_graph is true");
  if (!reduced_) return readOwnPoses(r, keyframes);
  hangs_.clear();
  const size_t n = r.count(5);
  if (n != keyframes) r.fail(std::to_string(n) + " keyframe nodes for " + std::to_string(keyframes) + " keyframes");
  for (size_t k = 0; k < n; ++k) {
    Hang h;
    h.node = r.i32();
    h.hung = r.boolean();
    if (h.node < 0 || h.node >= filter_.size()) r.fail("keyframe " + std::to_string(k) + " at filter pose " + std::to_string(h.node));
    if (h.hung) {
      h.offset = r.matrix<3, 1>();
      h.cov = r.matrix<3, 3>();
    }
    hangs_.push_back(h);
  }
  tail_ = r.size();
  if (tail_ >= kKeyframesPerPose || tail_ >= n) r.fail("a tail of " + std::to_string(tail_) + " keyframes");
  const size_t poses = r.count(1);
  if (poses != static_cast<size_t>(filter_.size()))
    r.fail(std::to_string(poses) + " closure counts for " + std::to_string(filter_.size()) + " filter poses");
  uses_.clear();
  for (size_t p = 0; p < poses; ++p) uses_.push_back(r.u8());
}

}  // namespace urbanslam::slam
