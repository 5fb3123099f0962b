#include "urbanslam/slam/KeyframeNodes.h"

#include <Eigen/LU>
#include <algorithm>
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

KeyframeNodes::KeyframeNodes(esdf::Esdf& filter, bool reduced) : filter_(filter), reduced_(reduced) {}

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
  if (reduced_) hangs_.push_back(Hang{filter_.size() - 1, false, Vec3::Zero(), Mat3::Zero()});
}

void KeyframeNodes::addOwn(size_t from, const Vec3& z, const Mat3& omega) {
  if (!reduced_) {
    filter_.augmentRelative(static_cast<int>(from), z, omega);
    return;
  }
  const Hang& f = hangs_.at(from);
  if (!f.hung) {
    filter_.augmentRelative(f.node, z, omega);
  } else {
    const Hang h = beyond(f, z, omega.inverse());
    filter_.augmentRelative(h.node, h.offset, addedToRight(h.offset, h.cov).inverse());
  }
  hangs_.push_back(Hang{filter_.size() - 1, false, Vec3::Zero(), Mat3::Zero()});
}

bool KeyframeNodes::add(size_t from, const Vec3& z, const Mat3& omega) {
  const bool after_closure = newest_closed_ && newest_closed_to_ == from && from + 1 == size();
  newest_closed_ = false;
  if (!reduced_ || !(hung(from) || after_closure)) {
    addOwn(from, z, omega);
    return true;
  }
  hangs_.push_back(beyond(hangs_[from], z, omega.inverse()));
  tail_.push_back(Link{from, z, omega});
  return false;
}

void KeyframeNodes::closed(size_t earlier, size_t k, const Vec3& z, const Mat3& cov) {
  if (!reduced_ || earlier >= k || inTail(earlier)) return;
  if (!inTail(k)) {
    // The newest keyframe, with a pose of its own, on mapped ground: the next hangs from it.
    if (!hung(k) && k + 1 == size()) {
      newest_closed_ = true;
      newest_closed_to_ = k;
    }
    return;
  }
  hangs_[k] = fused(hangs_[k], beyond(hangs_[earlier], z, cov));
  // The tail after k follows it by local SLAM's constraints.
  const size_t first = size() - tail_.size();
  for (size_t t = k + 1; t < size(); ++t) {
    const Link& l = tail_[t - first];
    hangs_[t] = beyond(hangs_[l.from], l.z, l.omega.inverse());
  }
  tail_.erase(tail_.begin(), tail_.begin() + static_cast<std::ptrdiff_t>(k + 1 - first));
}

KeyframeNodes::Hang KeyframeNodes::fused(const Hang& motion, const Hang& closure) {
  // Local SLAM's chain places a keyframe relative to its predecessor far better than a closure
  // does (on the cities a closure's position variance is 36 times a step's, median), so the
  // keyframe hangs from the closure's pose where both put it, each weighed by its covariance
  // (a Kalman update of the offset). The chain's offset is carried into that pose's frame by the
  // two filter poses' estimates, their relative uncertainty from the factors between them.
  Hang out = closure;
  Vec3 predicted = motion.offset;
  Mat3 predicted_cov = motion.cov;
  if (motion.node != closure.node) {
    Mat3 r_cov;
    if (!filter_.pathRelativeCovariance(closure.node, motion.node, &r_cov)) return closure;
    const Vec3 r = esdf::between(filter_.mean(closure.node), filter_.mean(motion.node));
    Mat3 j1, j2;
    esdf::composeJacobians(r, motion.offset, &j1, &j2);
    predicted = esdf::compose(r, motion.offset);
    predicted_cov = j1 * r_cov * j1.transpose() + j2 * motion.cov * j2.transpose();
  }
  const Mat3 gain = predicted_cov * (predicted_cov + closure.cov).inverse();
  out.offset = predicted + gain * esdf::poseDifference(closure.offset, predicted);
  const Mat3 c = (Mat3::Identity() - gain) * predicted_cov;
  out.cov = 0.5 * (c + c.transpose());
  return out;
}

void KeyframeNodes::promoteTail() {
  const size_t first = size() - tail_.size();
  for (size_t t = first; t < size(); ++t) {
    const Link& l = tail_[t - first];
    const Hang& f = hangs_[l.from];
    if (!f.hung) {
      filter_.augmentRelative(f.node, l.z, l.omega);
    } else {
      const Hang h = beyond(f, l.z, l.omega.inverse());
      filter_.augmentRelative(h.node, h.offset, addedToRight(h.offset, h.cov).inverse());
    }
    hangs_[t] = Hang{filter_.size() - 1, false, Vec3::Zero(), Mat3::Zero()};
  }
  tail_.clear();
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

void KeyframeNodes::toNodes(size_t i, size_t k, const Vec3& z, const Mat3& cov, Vec3* z_nodes, Mat3* cov_nodes) const {
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
  const Mat3 added = d_z * rightToAdded(z, cov) * d_z.transpose() + d_i * hi.cov * d_i.transpose() + d_k * hk.cov * d_k.transpose();
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
  return esdf::mahalanobisGate(nu, s, filter_.options().chi2_gate_probability);
}

esdf::ObservationResult KeyframeNodes::observeRelative(size_t i, size_t k, const Vec3& z, const Mat3& omega, bool gate) {
  if (!hung(i) && !hung(k)) return filter_.observeRelative(node(i), node(k), z, omega, gate);
  if (hangs_[i].node == hangs_[k].node) {
    esdf::ObservationResult r;
    if (gate) {
      r.gate = gateWithinNode(i, k, z, omega);
      r.accepted = r.gate.accepted;
    }
    return r;
  }
  Vec3 zn;
  Mat3 cn;
  toNodes(i, k, z, omega.inverse(), &zn, &cn);
  return filter_.observeRelative(hangs_[i].node, hangs_[k].node, zn, cn.inverse(), gate);
}

esdf::GateResult KeyframeNodes::gateRelative(size_t i, size_t k, const Vec3& z, const Mat3& omega) {
  if (!hung(i) && !hung(k)) return filter_.gateRelative(node(i), node(k), z, omega);
  if (hangs_[i].node == hangs_[k].node) return gateWithinNode(i, k, z, omega);
  Vec3 zn;
  Mat3 cn;
  toNodes(i, k, z, omega.inverse(), &zn, &cn);
  return filter_.gateRelative(hangs_[i].node, hangs_[k].node, zn, cn.inverse());
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
  w.size(tail_.size());
  for (const Link& l : tail_) {
    w.size(l.from);
    w.matrix(l.z);
    w.matrix(l.omega);
  }
  w.boolean(newest_closed_);
  if (newest_closed_) w.size(newest_closed_to_);
}

void KeyframeNodes::readOwnPoses(common::BinaryReader& r, size_t keyframes) {
  if (static_cast<size_t>(filter_.size()) != keyframes)
    r.fail("a filter of " + std::to_string(filter_.size()) + " poses for " + std::to_string(keyframes) + " keyframes");
  hangs_.clear();
  tail_.clear();
  newest_closed_ = false;
  if (reduced_)
    for (size_t k = 0; k < keyframes; ++k) hangs_.push_back(Hang{static_cast<int>(k), false, Vec3::Zero(), Mat3::Zero()});
}

void KeyframeNodes::readState(common::BinaryReader& r, size_t keyframes) {
  const bool reduced = r.boolean();
  if (reduced != reduced_)
    r.fail(reduced ? "keyframes hang from mapped places, but [estimator] reduced_pose_graph is false"
                   : "every keyframe has a pose of its own, but [estimator] reduced_pose_graph is true");
  if (!reduced_) return readOwnPoses(r, keyframes);
  hangs_.clear();
  tail_.clear();
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
  const size_t t = r.count(8 + 12 * 8);
  if (t > n) r.fail("a tail of " + std::to_string(t) + " keyframes");
  for (size_t i = 0; i < t; ++i) {
    Link l;
    l.from = r.size();
    if (l.from >= n) r.fail("a tail constraint from keyframe " + std::to_string(l.from));
    l.z = r.matrix<3, 1>();
    l.omega = r.matrix<3, 3>();
    tail_.push_back(l);
  }
  newest_closed_ = r.boolean();
  if (!newest_closed_) return;
  newest_closed_to_ = r.size();
  if (newest_closed_to_ >= n) r.fail("a closure of keyframe " + std::to_string(newest_closed_to_));
}

}  // namespace urbanslam::slam
