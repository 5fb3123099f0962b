#pragma once
// Which pose of the filter each keyframe is: its own, or one it hangs from (a reduced pose
// graph, after Johannsson et al. 2013).
//
// A keyframe of its own for every metre of every pass makes the filter grow with time rather
// than with the area, and the passes, linked by closures, thicken the whole-map factor with
// every one (bench/scale/RESULTS.md). Reduced, only every kKeyframesPerPose-th keyframe is a
// pose of the filter; the ones between hang from the last such pose by local SLAM's constraints
// (x_k = x_node ⊕ offset, the offset's covariance kept beside it), and the next pose is added
// from it by their composition. Where no closure falls in between, that is the chain with its
// inner poses marginalised out: exact.
//
// A closure of a hung keyframe goes into the filter between the two filter poses, its
// measurement composed with the offsets. A group's constraints are then in several measurements
// (its link and every closure through its offsets), so their information is shared out: the
// link takes 1 - kReserved of it, and the u-th closure through the group's offsets takes
// kReserved / 2^(u+1) (the offsets' covariance times 2^(u+1) / kReserved), which never adds up
// to more than there is: measurements that share a part whose information is split so are
// together never more certain than they are (for two, the difference of the covariances is
// [A; -B] S [A; -B]ᵀ ≥ 0). A closure whose offsets would weigh more than kMaxOffsetScale times
// their covariance is gated and adds nothing.
//
// Without reduction every keyframe is its own filter pose, and each call forwards unchanged.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

class KeyframeNodes {
 public:
  // Reduced: one keyframe in this many is a pose of the filter.
  static constexpr size_t kKeyframesPerPose = 4;
  // The share of a group's constraints' information kept from its link for closures through its
  // offsets, and the largest multiple of an offset's covariance a closure goes in with.
  static constexpr double kReserved = 0.1;
  static constexpr double kMaxOffsetScale = 1000;

  // `reduced`: whether keyframes may hang from others' poses; `own_poses_first`: the first this
  // many keyframes are poses of their own even so (the map's memory budget spent on them first).
  KeyframeNodes(esdf::Esdf& filter, bool reduced, size_t own_poses_first = 0);

  bool reduced() const { return reduced_; }
  size_t size() const { return reduced_ ? hangs_.size() : static_cast<size_t>(filter_.size()); }
  // Filter poses (never more than keyframes).
  int nodes() const { return filter_.size(); }
  int node(size_t k) const { return reduced_ ? hangs_[k].node : static_cast<int>(k); }
  bool hung(size_t k) const { return reduced_ && hangs_[k].hung; }
  // The keyframes hung since the filter's newest pose: the newest keyframes, at most.
  size_t tailSize() const { return tail_; }
  bool inTail(size_t k) const { return tail_ > 0 && k >= size() - tail_; }

  // The first keyframe: the filter's first pose (initialised by the caller).
  void addFirst();
  // The next keyframe, linked to keyframe `from` by z with information `omega`. It hangs (into
  // the tail) from `from`'s filter pose at from ⊕ z when `from` is the newest keyframe, the
  // first own_poses_first keyframes are in and the tail has room; else it becomes a pose of its
  // own by ESDF prediction with augmentation, z composed with `from`'s offset when that hangs.
  // True: a pose of its own.
  bool add(size_t from, const esdf::Vec3& z, const esdf::Mat3& omega);

  esdf::Vec3 mean(size_t k) const;
  esdf::Mat3 marginalCovariance(size_t k, esdf::CovarianceMode mode);
  // Covariance of ⊖x_i ⊕ x_k (i != k).
  esdf::Mat3 relativeCovariance(size_t i, size_t k, esdf::CovarianceMode mode);
  // Relative-pose observation of keyframe k from keyframe i, as Esdf::observeRelative. Gated
  // with its own covariance; where a keyframe hangs, it goes into the filter with its offsets'
  // share as the header says, or is gated and adds nothing.
  esdf::ObservationResult observeRelative(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega, bool gate);
  esdf::GateResult gateRelative(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega);
  // ... and its refusal when known without a factorisation (Esdf::refusalWithoutFactorising).
  std::optional<esdf::GateResult> refusalWithoutFactorising(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega);
  // The joint gate of two closures (Esdf::gateRelativePair) on the filter poses their keyframes
  // are or hang from; a closure within one filter pose has no map covariance to share: refused.
  esdf::GateResult gateRelativePair(size_t i1, size_t k1, const esdf::Vec3& z1, const esdf::Mat3& omega1, size_t i2, size_t k2,
                                    const esdf::Vec3& z2, const esdf::Mat3& omega2);
  double jointGateThreshold() const { return filter_.jointGateThreshold(); }
  double gateThreshold() const { return filter_.gateThreshold(); }
  void writeState(common::BinaryWriter& w) const;
  // After the filter's state; `keyframes`: the map's. Map format 10 hung keyframes otherwise:
  // such a map is refused.
  void readState(common::BinaryReader& r, size_t keyframes, std::uint32_t format_version);
  // A map file from before keyframes could hang: every keyframe its own filter pose.
  void readOwnPoses(common::BinaryReader& r, size_t keyframes);

 private:
  struct Hang {
    int node = 0;
    bool hung = false;
    esdf::Vec3 offset = esdf::Vec3::Zero();  // x_k = x_node ⊕ offset
    esdf::Mat3 cov = esdf::Mat3::Zero();     // the offset's
  };
  // `h` ⊕ z with covariance cov: where a keyframe at z from h's keyframe hangs.
  static Hang beyond(const Hang& h, const esdf::Vec3& z, const esdf::Mat3& cov);
  // The relative pose between the filter poses of i and k that a measurement z of ⊖x_i ⊕ x_k
  // with covariance cov makes, and that one's covariance (i's and k's offsets' covariances
  // times scale_i and scale_k).
  void toNodes(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& cov, double scale_i, double scale_k,
               esdf::Vec3* z_nodes, esdf::Mat3* cov_nodes) const;
  esdf::GateResult gateWithinNode(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega) const;
  // gateRelative, and refusalWithoutFactorising's answer before it drops an admission.
  std::optional<esdf::GateResult> gate(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega, bool without_factorising);
  // The filter poses of closure (i, k) and its measurement and information between them; false
  // when both keyframes hang from one pose.
  bool onNodes(size_t i, size_t k, const esdf::Vec3& z, const esdf::Mat3& omega, int* a, int* b, esdf::Vec3* z_nodes,
               esdf::Mat3* omega_nodes) const;
  // The multiple of keyframe k's offset covariance its next closure goes in with (1: no offset).
  double offsetScale(size_t k) const;

  esdf::Esdf& filter_;
  bool reduced_;
  size_t own_poses_first_;
  std::deque<Hang> hangs_;  // per keyframe (reduced only)
  size_t tail_ = 0;         // keyframes hung since the newest filter pose
  std::deque<std::uint8_t> uses_;  // per filter pose: closures through its group's offsets so far
};

}  // namespace urbanslam::slam
