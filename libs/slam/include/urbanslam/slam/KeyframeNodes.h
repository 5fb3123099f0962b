#pragma once
// Which pose of the filter each keyframe is: its own, or one it hangs from (a reduced pose
// graph, Johannsson et al. 2013).
//
// Driving over mapped streets, a keyframe of its own for every metre of every pass makes the
// filter grow with time rather than with the area, and the passes, linked by closures, thicken
// the whole-map factor with every one (bench/scale/RESULTS.md). Where a keyframe closes with an
// earlier one, it is instead hung from that keyframe's filter pose at the closure's measurement
// (x_k = x_node ⊕ offset, the offset's covariance kept beside it); the keyframes that follow
// hang from the same pose by local SLAM's constraints until one closes again or the vehicle
// leaves mapped ground, when they get poses of their own, each linked as it would have been.
// A closure of a hung keyframe goes into the filter between the two filter poses, its
// measurement composed with the offsets (their covariances added), so the pass adds
// information to the poses already there and no pose. Offsets are treated as independent of
// the filter's poses and of each other: consecutive closures share a measurement, which makes
// the filter overconfident along their difference by at most half.
//
// Without reduction every keyframe is its own filter pose, and each call forwards unchanged.
#include <Eigen/Core>
#include <cstdint>
#include <deque>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

class KeyframeNodes {
 public:
  // `reduced`: whether keyframes may hang from others' poses.
  KeyframeNodes(esdf::Esdf& filter, bool reduced);

  bool reduced() const { return reduced_; }
  size_t size() const { return reduced_ ? hangs_.size() : static_cast<size_t>(filter_.size()); }
  // Filter poses (never more than keyframes).
  int nodes() const { return filter_.size(); }
  int node(size_t k) const { return reduced_ ? hangs_[k].node : static_cast<int>(k); }
  bool hung(size_t k) const { return reduced_ && hangs_[k].hung; }
  // Hung by local SLAM's constraints alone, awaiting a closure or a pose of its own: the newest
  // keyframes, at most.
  size_t tailSize() const { return tail_.size(); }
  bool inTail(size_t k) const { return !tail_.empty() && k >= size() - tail_.size(); }

  // The first keyframe: the filter's first pose (initialised by the caller).
  void addFirst();
  // The next keyframe, linked to keyframe `from` by z with information `omega`. It hangs (into
  // the tail) from `from`'s filter pose at from ⊕ z when `from` hangs, or when `from` is the
  // newest keyframe and has just closed with an earlier one (closed()); else it becomes a pose of
  // its own by ESDF prediction with augmentation, z composed with `from`'s offset when that
  // hangs. True: a pose of its own.
  bool add(size_t from, const esdf::Vec3& z, const esdf::Mat3& omega);
  // An accepted closure: keyframe k's pose in earlier's frame is z (covariance cov), already in
  // the filter. A tail keyframe then hangs from earlier's pose, where the closure and local
  // SLAM's chain put it, each weighed by its covariance; the tail keyframes after it follow it,
  // and the tail up to it leaves the tail. The newest keyframe with a pose of its own starts
  // mapped ground for the next.
  void closed(size_t earlier, size_t k, const esdf::Vec3& z, const esdf::Mat3& cov);
  // The tail keyframes get poses of their own, each linked to its predecessor by its constraint
  // (composed with the offset of a predecessor that hangs).
  void promoteTail();

  esdf::Vec3 mean(size_t k) const;
  esdf::Mat3 marginalCovariance(size_t k, esdf::CovarianceMode mode);
  // Covariance of ⊖x_i ⊕ x_k (i != k).
  esdf::Mat3 relativeCovariance(size_t i, size_t k, esdf::CovarianceMode mode);
  // Relative-pose observation of keyframe k from keyframe i, as Esdf::observeRelative. Between
  // two keyframes of one filter pose, the observation is gated against their offsets and adds
  // nothing to the filter.
  esdf::ObservationResult observeRelative(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega, bool gate);
  esdf::GateResult gateRelative(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega);
  void writeState(common::BinaryWriter& w) const;
  // After the filter's state; `keyframes`: the map's.
  void readState(common::BinaryReader& r, size_t keyframes);
  // A map file from before keyframes could hang: every keyframe its own filter pose.
  void readOwnPoses(common::BinaryReader& r, size_t keyframes);

 private:
  struct Hang {
    int node = 0;
    bool hung = false;
    esdf::Vec3 offset = esdf::Vec3::Zero();  // x_k = x_node ⊕ offset
    esdf::Mat3 cov = esdf::Mat3::Zero();     // the offset's
  };
  // A tail keyframe's constraint from its predecessor, for its promotion.
  struct Link {
    size_t from = 0;
    esdf::Vec3 z = esdf::Vec3::Zero();
    esdf::Mat3 omega = esdf::Mat3::Identity();  // information
  };
  void addOwn(size_t from, const esdf::Vec3& z, const esdf::Mat3& omega);
  // Where the chain (`motion`) and a closure (`closure`) put a keyframe, in the closure's pose.
  Hang fused(const Hang& motion, const Hang& closure);
  // `h` ⊕ z with covariance cov: where a keyframe at z from h's keyframe hangs.
  static Hang beyond(const Hang& h, const esdf::Vec3& z, const esdf::Mat3& cov);
  // The relative pose between the filter poses of i and k that a measurement z of ⊖x_i ⊕ x_k
  // with covariance cov makes, and that one's covariance.
  void toNodes(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& cov, esdf::Vec3* z_nodes, esdf::Mat3* cov_nodes) const;
  esdf::GateResult gateWithinNode(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega) const;

  esdf::Esdf& filter_;
  bool reduced_;
  std::deque<Hang> hangs_;  // per keyframe (reduced only)
  std::deque<Link> tail_;   // the tail keyframes' constraints, oldest first
  // The newest keyframe closed while it had a pose of its own (none when it is not the newest
  // any more): the next keyframe hangs from it.
  bool newest_closed_ = false;
  size_t newest_closed_to_ = 0;
};

}  // namespace urbanslam::slam
